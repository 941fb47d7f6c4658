#include "formats/output_stream.hpp"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <unistd.h>

#include "cli/errors.hpp"

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

OutputStream::OutputStream(const std::string& path) : buffer_(buffer_size) {
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
  temp_path_ = path + ".partial-" + std::to_string(::getpid());
  file_ = std::fopen(temp_path_.c_str(), "wb");
  if (!file_) throw IoError("cannot create " + path + ": " + errno_text());
  watch_temp(temp_path_);
}

OutputStream::~OutputStream() {
  if (is_stdout_ || committed_) return;
  if (file_) std::fclose(file_);
  if (direct_) return;
  std::error_code ignored;
  std::filesystem::remove(temp_path_, ignored);
  unwatch_temp();
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
    committed_ = true;
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

}  // namespace hemotree
