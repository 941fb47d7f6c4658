// Buffered output that never leaves a file looking complete when it is not:
// a named file is written under a temporary name and renamed by commit();
// standard output is checked for write errors (full disk, closed pipe).
#pragma once

#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

namespace hemotree {

class OutputStream {
 public:
  // path "-" or "" means standard output.
  explicit OutputStream(const std::string& path);
  ~OutputStream();  // without commit(): the temporary file is removed
  OutputStream(const OutputStream&) = delete;
  OutputStream& operator=(const OutputStream&) = delete;

  void write(std::string_view bytes);
  OutputStream& operator<<(std::string_view bytes) { write(bytes); return *this; }
  OutputStream& operator<<(char c) { write(std::string_view(&c, 1)); return *this; }
  OutputStream& operator<<(double value);        // 9 significant digits, round-trip stable
  OutputStream& operator<<(long long value);
  OutputStream& operator<<(int value) { return *this << static_cast<long long>(value); }
  OutputStream& operator<<(long value) { return *this << static_cast<long long>(value); }
  OutputStream& operator<<(unsigned long value) { return *this << static_cast<long long>(value); }

  // Flushes, checks, closes and renames into place. Throws hemotree::IoError on failure.
  void commit();
  const std::string& name() const { return display_name_; }

 private:
  void flush_buffer();
  std::FILE* file_ = nullptr;
  bool is_stdout_ = false;
  bool direct_ = false;  // a device or pipe given by name: written in place
  bool committed_ = false;
  std::string final_path_, temp_path_, display_name_;
  std::vector<char> buffer_;
  std::size_t used_ = 0;
};

// Formats a real number with 9 significant digits (the precision of the network format).
// Returns the number of characters written to out (at most 24).
std::size_t format_real(char* out, double value);

}  // namespace hemotree
