// Buffered output that never leaves a file looking complete when it is not, nor a stray
// temporary after the writer is killed:
// - a named file is written into an anonymous file in the target's folder (O_TMPFILE),
//   which commit() links in at the target's name when there is none yet, else under
//   NAME.partial-HOST-PID renamed over the target at once; killed at any moment, even by
//   SIGKILL, the writer leaves the target as it was, and no other name, except after a
//   SIGKILL between those last two system calls: that NAME.partial-HOST-PID, which the next
//   writer of NAME removes;
// - where the file system has no O_TMPFILE (NFS, old overlayfs), into NAME.partial-HOST-PID,
//   removed on failure, on SIGINT, SIGTERM and SIGHUP, and, after a SIGKILL, by the next
//   writer of NAME once no process PID runs on HOST;
// - standard output is checked for write errors (full disk, closed pipe); what a tool
//   prints outside an OutputStream, run_tool checks (cli/tool.hpp).
#pragma once

#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

namespace hemotree {

class OutputStream {
 public:
  enum class Temporary { anonymous_if_possible, named };

  // path "-" or "" means standard output. Temporary::named forces the fallback (for tests).
  explicit OutputStream(const std::string& path,
                        Temporary temporary = Temporary::anonymous_if_possible);
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
  // Where the bytes go until commit(): "" for an anonymous file, else NAME.partial-HOST-PID.
  const std::string& temporary_path() const { return temp_path_; }
  // A path through which a library that writes files by name (HDF5) writes this file's bytes
  // itself, before any write() and before commit(): the named temporary (an anonymous file
  // is traded for one: HDF5 resolves a /proc/self/fd link to a name that does not exist);
  // "" for standard output and devices, which take bytes through write() only.
  std::string path_for_writer();

 private:
  void flush_buffer();
  void commit_anonymous();
  std::FILE* file_ = nullptr;
  bool is_stdout_ = false;
  bool direct_ = false;     // a device or pipe given by name: written in place
  bool anonymous_ = false;  // an O_TMPFILE file, linked in by commit()
  bool committed_ = false;
  std::string final_path_, temp_path_, display_name_;
  std::vector<char> buffer_;
  std::size_t used_ = 0;
};

// The fallback temporary's name for path on this host and process: path.partial-HOST-PID.
std::string partial_path(const std::string& path);

// Removes path.partial-HOST-PID (this host) and path.partial-PID (the older form) files whose
// process no longer runs: what a writer killed by SIGKILL left. Returns how many it removed.
std::size_t remove_stale_partials(const std::string& path);

// Formats a real number with 9 significant digits (the precision of the network format).
// Returns the number of characters written to out (at most 24).
std::size_t format_real(char* out, double value);

}  // namespace hemotree
