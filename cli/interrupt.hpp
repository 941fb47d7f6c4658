// Ctrl-C and kill (SIGINT, SIGTERM, SIGHUP) as requests that a long run answers at a point of
// its own choosing (a step's end): while an InterruptRequests lives, those signals are
// blocked in every thread and polled, so no handler can end the program halfway through a
// step or a file, and the run can save what it has before it stops. (<csignal> stays out of
// this header: its macros, such as si_value, clash with ordinary names.)
#pragma once

#include <memory>

namespace hemotree {

// Thrown to leave a tool at once on a request (run_tool returns the status): for a stage
// that has nothing to save.
struct InterruptedExit {
  int status;
};

class InterruptRequests {
 public:
  // Blocks the signals; threads started afterwards (OpenMP's) inherit the mask.
  InterruptRequests();
  ~InterruptRequests();  // unblocks them; one still pending is then delivered as usual
  InterruptRequests(const InterruptRequests&) = delete;
  InterruptRequests& operator=(const InterruptRequests&) = delete;

  // The signal number of a pending request (consumed), or 0. A system call: poll every few
  // hundred steps, not every step.
  int poll();
  // 128 + the signal: the shell's status for a program that a signal stopped.
  static int exit_status(int signal_number) { return 128 + signal_number; }
  static const char* name(int signal_number);

 private:
  struct Masks;
  std::unique_ptr<Masks> masks_;
};

}  // namespace hemotree
