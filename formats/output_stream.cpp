#include "formats/output_stream.hpp"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <csignal>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <string_view>
#include <unistd.h>

#include "core/errors.hpp"

namespace hemotree {

namespace {
constexpr std::size_t buffer_size = 1 << 20;

std::string errno_text() { return std::strerror(errno); }

// The temporary file being written, removed if the program is interrupted (Ctrl-C, kill)
// so that no stray partial file stays behind. One output file at a time per process.
char pending_temp[4096] = "";

extern "C" void remove_pending_and_reraise(int signal_number) {
  if (pending_temp[0] != '\0') ::unlink(pending_temp);  // async-signal-safe
  std::signal(signal_number, SIG_DFL);
  std::raise(signal_number);
}

void watch_temp(const std::string& path) {
  if (path.size() >= sizeof pending_temp) return;
  std::memcpy(pending_temp, path.c_str(), path.size() + 1);
  std::signal(SIGINT, remove_pending_and_reraise);
  std::signal(SIGTERM, remove_pending_and_reraise);
  std::signal(SIGHUP, remove_pending_and_reraise);
}

void unwatch_temp() { pending_temp[0] = '\0'; }

// This machine's name as it can stand in a file name ('/' would make it a folder).
std::string host_name() {
  char name[256] = "";
  if (::gethostname(name, sizeof name - 1) != 0 || name[0] == '\0') return "localhost";
  std::string text(name);
  for (char& c : text)
    if (c == '/' || c < ' ') c = '_';
  return text;
}
}  // namespace

std::size_t format_real(char* out, double value) {
  if (value == 0.0) {
    out[0] = '0';
    return 1;
  }
  // JSON has no inf/nan: a non-finite value here is a bug upstream, never data.
  if (!std::isfinite(value)) throw std::logic_error("non-finite number in network output");
  auto res = std::to_chars(out, out + 32, value, std::chars_format::general, 9);
  return static_cast<std::size_t>(res.ptr - out);
}

std::string partial_path(const std::string& path) {
  return path + ".partial-" + host_name() + "-" + std::to_string(::getpid());
}

std::size_t remove_stale_partials(const std::string& path) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path folder = target.has_parent_path() ? target.parent_path() : fs::path(".");
  const std::string prefix = target.filename().string() + ".partial-";
  const std::string host = host_name();
  std::size_t removed = 0;
  std::error_code ec;
  for (fs::directory_iterator it(folder, fs::directory_options::skip_permission_denied, ec), end;
       !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.compare(0, prefix.size(), prefix) != 0) continue;
    // PID alone (the older form) or HOST-PID; another host's file is never touched, since
    // its process cannot be seen from here (a folder shared over NFS).
    std::string_view rest = std::string_view(name).substr(prefix.size());
    const std::size_t dash = rest.rfind('-');
    if (dash != std::string_view::npos) {
      if (rest.substr(0, dash) != host) continue;
      rest.remove_prefix(dash + 1);
    }
    long long pid = 0;
    const auto [stop, parse_error] = std::from_chars(rest.data(), rest.data() + rest.size(), pid);
    if (parse_error != std::errc() || stop != rest.data() + rest.size() || pid <= 0) continue;
    if (pid == ::getpid()) continue;
    // Only a process that is certainly gone: EPERM means it runs under another user.
    if (pid <= std::numeric_limits<pid_t>::max() && ::kill(static_cast<pid_t>(pid), 0) == 0) continue;
    if (pid <= std::numeric_limits<pid_t>::max() && errno != ESRCH) continue;
    std::error_code ignored;
    if (fs::remove(it->path(), ignored)) ++removed;
  }
  return removed;
}

OutputStream::OutputStream(const std::string& path, Temporary temporary) : buffer_(buffer_size) {
  if (path.empty() || path == "-") {
    // A closed pipe must become a write error we can report, not a silent death.
    std::signal(SIGPIPE, SIG_IGN);
    file_ = stdout;
    is_stdout_ = true;
    display_name_ = "standard output";
    return;
  }
  final_path_ = path;
  display_name_ = path;
  std::error_code ec;
  if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec)) {
    // A device or a named pipe (/dev/full, a FIFO): nothing to rename, write straight in.
    file_ = std::fopen(path.c_str(), "wb");
    if (!file_) throw IoError("cannot open " + path + ": " + errno_text());
    direct_ = true;
    return;
  }
  remove_stale_partials(path);
  if (temporary == Temporary::anonymous_if_possible) {
    const std::filesystem::path target(path);
    const std::string folder = target.has_parent_path() ? target.parent_path().string() : ".";
    // commit() links the file in through /proc/self/fd: without /proc, the named fallback.
    const int fd = ::access("/proc/self/fd", X_OK) == 0
                       ? ::open(folder.c_str(), O_TMPFILE | O_WRONLY | O_CLOEXEC, 0666)
                       : -1;
    if (fd >= 0) {
      file_ = ::fdopen(fd, "wb");
      if (!file_) {
        ::close(fd);
        throw IoError("cannot create " + path + ": " + errno_text());
      }
      anonymous_ = true;
      return;
    }
  }
  temp_path_ = partial_path(path);
  file_ = std::fopen(temp_path_.c_str(), "wb");
  if (!file_) throw IoError("cannot create " + path + ": " + errno_text());
  watch_temp(temp_path_);
}

OutputStream::~OutputStream() {
  if (is_stdout_ || committed_) return;
  if (file_) std::fclose(file_);  // an anonymous file vanishes with its last descriptor
  if (direct_ || temp_path_.empty()) return;
  std::error_code ignored;
  std::filesystem::remove(temp_path_, ignored);
  unwatch_temp();
}

std::string OutputStream::path_for_writer() {
  if (is_stdout_ || direct_) return "";
  if (anonymous_) {
    if (used_ != 0 || std::ftell(file_) != 0) throw std::logic_error(display_name_ + ": path_for_writer after a write");
    std::fclose(file_);  // nothing in it: it vanishes
    file_ = nullptr;
    anonymous_ = false;
    temp_path_ = partial_path(final_path_);
    file_ = std::fopen(temp_path_.c_str(), "wb");
    if (!file_) throw IoError("cannot create " + final_path_ + ": " + errno_text());
    watch_temp(temp_path_);
  }
  return temp_path_;
}

void OutputStream::flush_buffer() {
  if (used_ == 0) return;
  if (std::fwrite(buffer_.data(), 1, used_, file_) != used_)
    throw IoError("cannot write " + display_name_ + ": " + errno_text());
  used_ = 0;
}

void OutputStream::write(std::string_view bytes) {
  if (bytes.size() > buffer_.size() - used_) {
    flush_buffer();
    if (bytes.size() > buffer_.size()) {
      if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size())
        throw IoError("cannot write " + display_name_ + ": " + errno_text());
      return;
    }
  }
  std::memcpy(buffer_.data() + used_, bytes.data(), bytes.size());
  used_ += bytes.size();
}

OutputStream& OutputStream::operator<<(double value) {
  char text[32];
  write(std::string_view(text, format_real(text, value)));
  return *this;
}

OutputStream& OutputStream::operator<<(long long value) {
  char text[24];
  auto res = std::to_chars(text, text + sizeof text, value);
  write(std::string_view(text, static_cast<std::size_t>(res.ptr - text)));
  return *this;
}

void OutputStream::commit() {
  flush_buffer();
  if (std::fflush(file_) != 0) throw IoError("cannot write " + display_name_ + ": " + errno_text());
  if (is_stdout_) {
    // Closing a duplicate reports what a file system defers to close (NFS), without closing
    // standard output itself.
    const int copy = ::dup(STDOUT_FILENO);
    if (std::ferror(stdout) || (copy >= 0 && ::close(copy) != 0))
      throw IoError("cannot write " + display_name_ + ": " + errno_text());
    committed_ = true;
    return;
  }
  if (anonymous_) {
    commit_anonymous();
    return;
  }
  if (std::fclose(file_) != 0) {
    file_ = nullptr;
    throw IoError("cannot write " + display_name_ + ": " + errno_text());
  }
  file_ = nullptr;
  if (direct_) {
    committed_ = true;
    return;
  }
  std::error_code ec;
  std::filesystem::rename(temp_path_, final_path_, ec);
  if (ec) throw IoError("cannot rename into " + final_path_ + ": " + ec.message());
  unwatch_temp();
  committed_ = true;
}

// The complete file gets a name only now. linkat() cannot replace a file: a new target is
// linked in at its own name, atomically and with no other name ever seen; an existing one is
// replaced by rename() from NAME.partial-HOST-PID, the very next system call, so that only a
// SIGKILL between the two can leave that name behind (and the next writer of NAME removes it).
void OutputStream::commit_anonymous() {
  // Closed before linking, so that no write error can come after the file is in place; a
  // duplicate descriptor keeps the unnamed file alive meanwhile.
  const int fd = ::dup(::fileno(file_));
  if (fd < 0) throw IoError("cannot write " + display_name_ + ": " + errno_text());
  const int closed = std::fclose(file_);
  file_ = nullptr;
  if (closed != 0) {
    const std::string why = errno_text();
    ::close(fd);
    throw IoError("cannot write " + display_name_ + ": " + why);
  }
  const std::string fd_path = "/proc/self/fd/" + std::to_string(fd);
  const auto link_as = [&](const std::string& name) {
    return ::linkat(AT_FDCWD, fd_path.c_str(), AT_FDCWD, name.c_str(), AT_SYMLINK_FOLLOW) == 0;
  };
  if (!link_as(final_path_)) {
    if (errno != EEXIST) {
      const std::string why = errno_text();
      ::close(fd);
      throw IoError("cannot create " + final_path_ + ": " + why);
    }
    temp_path_ = partial_path(final_path_);
    watch_temp(temp_path_);  // SIGINT, SIGTERM or SIGHUP between the two calls remove it
    // A partial under this process's own id can only be a killed writer's whose id this
    // process reuses (remove_stale_partials spares our own): it goes.
    if (!link_as(temp_path_) && !(errno == EEXIST && ::unlink(temp_path_.c_str()) == 0 && link_as(temp_path_))) {
      const std::string why = errno_text();
      temp_path_.clear();
      unwatch_temp();
      ::close(fd);
      throw IoError("cannot create " + final_path_ + ": " + why);
    }
    if (::rename(temp_path_.c_str(), final_path_.c_str()) != 0) {
      const std::string why = errno_text();
      ::close(fd);  // the destructor removes temp_path_
      throw IoError("cannot rename into " + final_path_ + ": " + why);
    }
    unwatch_temp();
  }
  ::close(fd);
  committed_ = true;
}

}  // namespace hemotree
