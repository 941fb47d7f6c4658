// What a run says while it runs, and how it is asked to stop. The run's library knows no
// terminal and no signal: the tool (hemosolve: stderr and Ctrl-C, cli/) implements this, and
// so may a test, a benchmark or a binding. Every method has a silent default.
#pragma once

#include <string>

namespace hemotree {

// How progress within a run is shown: not at all, as a line redrawn in place (a terminal),
// or as a line per cycle (a log).
enum class ProgressStyle { none, live, log };

class RunObserver {
 public:
  virtual ~RunObserver() = default;
  // What the run does, in words (the step, the cost, the results' folder).
  virtual void note(const std::string& message) { (void)message; }
  // What must be heard even by a quiet run (a start from rest, unphysiological pressures).
  virtual void warn(const std::string& message) { (void)message; }
  // Whether notes are heard: a warning about cost alone is said only to whom hears notes.
  virtual bool hears_notes() const { return false; }
  virtual ProgressStyle progress_style() const { return ProgressStyle::none; }
  // The live line: cycle (1-based) of planned, the solver's time [s], steps per second and
  // the seconds left in this cycle; cleared at a cycle's end, an interrupt or a breakdown.
  virtual void live_progress(int cycle, int planned, double time, double steps_per_second, double seconds_left) {
    (void)cycle, (void)planned, (void)time, (void)steps_per_second, (void)seconds_left;
  }
  virtual void clear_live_progress() {}
  // The signal number of a pending request to stop (consumed), or 0. Polled every few
  // hundred steps: it may be a system call.
  virtual int poll_interrupt() { return 0; }
  // The request's name in messages ("SIGINT").
  virtual std::string signal_name(int signal) const { return "signal " + std::to_string(signal); }
};

}  // namespace hemotree
