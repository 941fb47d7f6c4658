// A file name in a folder of the system's temporary folder that no other test process
// shares (ctest runs tests in parallel, each in its own process, so a fixed name would be a
// race), removed with everything in it when the process ends: a test run leaves nothing
// behind.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>

namespace hemotree {

class ScratchFolder {
 public:
  ScratchFolder() : path_(std::filesystem::temp_directory_path() / ("hemotree-test-" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(path_);
  }
  ~ScratchFolder() {
    std::error_code ignored;  // a process forked by a death test leaves the folder to its parent
    if (owner_ == ::getpid()) std::filesystem::remove_all(path_, ignored);
  }
  ScratchFolder(const ScratchFolder&) = delete;
  ScratchFolder& operator=(const ScratchFolder&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  pid_t owner_ = ::getpid();
};

inline std::filesystem::path scratch_path(const std::string& name) {
  static ScratchFolder folder;
  return folder.path() / name;
}

}  // namespace hemotree
