#include "formats/hdf5_crash_guard.hpp"

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <iterator>

#include <unistd.h>

namespace hemotree::hdf5 {

namespace {

// The crash guard's state: the line to print, the handlers it replaced, how many guards.
char crash_line[1024];
std::size_t crash_line_length = 0;
constexpr int guarded_signals[] = {SIGSEGV, SIGBUS, SIGABRT, SIGFPE, SIGILL};
struct sigaction replaced[std::size(guarded_signals)];
int guards = 0;

extern "C" void report_library_crash(int signal_number) {
  // Only async-signal-safe calls (write, _exit), and the line in one write, so that it is not
  // split by what another process writes to the same terminal.
  char line[sizeof crash_line + 8];
  std::size_t n = 0;
  for (; n < crash_line_length; ++n) line[n] = crash_line[n];
  if (signal_number >= 10) line[n++] = static_cast<char>('0' + signal_number / 10 % 10);
  line[n++] = static_cast<char>('0' + signal_number % 10);
  line[n++] = ')';
  line[n++] = '\n';
  const ssize_t written = ::write(STDERR_FILENO, line, n);
  (void)written;
  ::_exit(2);
}

}  // namespace

CrashGuard::CrashGuard(const std::string& file_name) {
  active_ = true;
  if (guards++ > 0) return;
  const std::string line = std::string(program_invocation_short_name) + ": error: " + file_name +
                           ": damaged HDF5 file (the HDF5 library failed reading it: signal ";
  crash_line_length = std::min(line.size(), sizeof crash_line);
  std::memcpy(crash_line, line.data(), crash_line_length);
  struct sigaction action{};
  action.sa_handler = report_library_crash;
  sigemptyset(&action.sa_mask);
  for (std::size_t k = 0; k < std::size(guarded_signals); ++k) sigaction(guarded_signals[k], &action, &replaced[k]);
}

void CrashGuard::release() {
  if (!active_) return;
  active_ = false;
  if (--guards > 0) return;
  for (std::size_t k = 0; k < std::size(guarded_signals); ++k) sigaction(guarded_signals[k], &replaced[k], nullptr);
}

}  // namespace hemotree::hdf5
