// What every fuzz harness shares: the errors a hostile input may raise, a scratch folder
// outside the repository, and the rule that anything else is a finding.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "core/errors.hpp"
#include "formats/json_pull.hpp"

namespace hemotree::fuzz {

// Where findings are told: a copy of stderr taken at start, before libFuzzer's
// -close_fd_mask silences the tools' own messages.
inline int& report_fd() {
  static int fd = -1;
  return fd;
}
inline void keep_report_channel() {
  if (report_fd() < 0) report_fd() = ::dup(2);
}

// A finding: libFuzzer sees the abort, keeps the input as crash-* and stops.
[[noreturn]] inline void finding(const std::string& what) {
  ::dprintf(report_fd() >= 0 ? report_fd() : 2, "\nFUZZ FINDING: %s\n", what.c_str());
  std::abort();
}

// How a hostile input may end: a result, or one of the project's errors with its message.
struct Refusal {
  std::string kind;     // "InputError", "JsonError" or "IoError"
  std::string message;  // what()
  bool operator==(const Refusal&) const = default;
};

// Runs f and returns its value, or the project's error it threw. Any other exception (a
// library's own, a logic_error, ...) would reach the user as an internal error: a finding.
template <class F>
auto outcome(const char* stage, F f) -> std::pair<std::optional<decltype(f())>, Refusal> {
  try {
    return {f(), {}};
  } catch (const InputError& e) {
    return {std::nullopt, {"InputError", e.what()}};
  } catch (const JsonError& e) {
    return {std::nullopt, {"JsonError", e.what()}};
  } catch (const IoError& e) {
    return {std::nullopt, {"IoError", e.what()}};
  } catch (const std::exception& e) {
    finding(std::string(stage) + ": an exception that is not the project's (internal error, exit 70): " +
            e.what());
  } catch (...) {
    finding(std::string(stage) + ": a non-standard exception");
  }
}

// A folder of the harness's own under $TMPDIR (or /dev/shm, which is memory), removed at exit.
inline const std::filesystem::path& scratch() {
  static const std::filesystem::path dir = [] {
    const char* base = std::getenv("TMPDIR");
    std::string root = base && *base ? base : (std::filesystem::is_directory("/dev/shm") ? "/dev/shm" : "/tmp");
    std::filesystem::path d = std::filesystem::path(root) / ("hemotree-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(scratch(), ec);
    });
    return d;
  }();
  return dir;
}

inline void write_file(const std::filesystem::path& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) finding("the harness cannot write its scratch file " + path.string());
}

inline std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) finding("the harness cannot read " + path.string());
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace hemotree::fuzz
