// Where the tests find the shared public networks (../shared/networks beside the project,
// or HEMOTREE_NETWORKS_DIR): read at run time, never copied in. The tests that need them
// skip, saying so, where a clone has no ../shared; beside it they run (CI and scripts/test).
#pragma once

#include <cstdlib>
#include <filesystem>

namespace hemotree {

inline std::filesystem::path shared_networks_dir() {
  if (const char* env = std::getenv("HEMOTREE_NETWORKS_DIR")) return env;
  return std::filesystem::path(HEMOTREE_SOURCE_DIR) / ".." / "shared" / "networks";
}

// The rat mesentery of Pries et al. in Secomb's network.dat.
inline std::filesystem::path shared_mesentery() { return shared_networks_dir() / "mesentery-rat" / "network.dat"; }

}  // namespace hemotree
