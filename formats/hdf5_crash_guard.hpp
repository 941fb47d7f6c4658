// A guard over the HDF5 library while it reads a file from outside.
#pragma once

#include <string>
#include <utility>

namespace hemotree::hdf5 {

// HDF5 1.10 trusts a file's metadata: of the single-byte flips of a small network file, about
// one in a thousand made the library itself crash (segmentation faults, heap corruption found
// by glibc), where the others are refused (or land where nothing is read). While a file from
// outside is open, such a crash becomes the one line every bad input gets,
// "TOOL: error: FILE: damaged HDF5 file (the HDF5 library failed reading it: signal N)", and
// exit status 2. Nested guards are one; the handlers before are restored when the last ends.
class CrashGuard {
 public:
  CrashGuard() = default;
  explicit CrashGuard(const std::string& file_name);
  CrashGuard(CrashGuard&& other) noexcept : active_(std::exchange(other.active_, false)) {}
  CrashGuard& operator=(CrashGuard&& other) noexcept {
    if (this != &other) {
      release();
      active_ = std::exchange(other.active_, false);
    }
    return *this;
  }
  ~CrashGuard() { release(); }

 private:
  void release();
  bool active_ = false;
};

}  // namespace hemotree::hdf5
