// A file name in the system's temporary folder that no other test process shares: ctest
// runs tests in parallel, each in its own process, so a fixed name would be a race.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

namespace hemotree {

inline std::filesystem::path scratch_path(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("hemotree-" + std::to_string(::getpid()) + "-" + name);
}

}  // namespace hemotree
