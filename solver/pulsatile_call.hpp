// A run as a library call: a network and a run configuration in, the results folder written
// (summary.json, vessels.csv, probes.csv, results.vtp, frames, checkpoint) and the outcome
// out, with no command line. hemosolve, a test, a benchmark or a binding calls these; what
// the run says and how it is stopped go through a RunObserver.
#pragma once

#include <cstdint>
#include <string>

#include "formats/network.hpp"
#include "solver/cycle_statistics.hpp"
#include "solver/run_configuration.hpp"
#include "solver/run_observer.hpp"
#include "solver/run_outcome.hpp"

namespace hemotree {

struct RunResult {
  RunOutcome outcome = RunOutcome::complete;
  int signal = 0;             // interrupted: the request's signal
  bool started = true;        // false: interrupted before the first step, nothing written
  std::string error;          // broken_down: the breakdown; failed: what is wrong with the results
  int cycles_done = 0;
  // The last cycle-to-cycle change of the mean pressures (after two cycles) and where it is largest.
  bool has_change = false;
  double change = 0;
  std::int64_t slowest_vessel = -1;  // its id
  double time_step = 0;              // [s], a whole number per cycle
  std::size_t steps_per_cycle = 0;
  CycleSummary last_cycle;           // the statistics of the last whole cycle (empty before one)
};

// What a pulsatile run needs of the network and the configuration together: boundary
// conditions, and a probe interval within the period (InputError otherwise).
void check_pulsatile(const Network& net, const RunConfiguration& config);

// The pulsatile run: the solver set up (the steady start: minutes on a full tree), the step
// decided (decide_time_step), the cycles run, their numbers checked (mass kept, each
// prescribed mean flow followed, no forced step) and the folder published. InputError for a
// run that cannot start or that breaks down before a whole cycle (nothing kept), a cycle
// estimated or measured above a day (unless forced) or a checkpoint of another run.
RunResult run_pulsatile(const Network& net, const RunConfiguration& config, RunObserver& observer);
// The same over a network the caller gives up (hemosolve's): once its identity is taken, what
// no output of this run reads is freed (the node coordinates, 24 B a node, without --vtk and
// --frames), and the network is left so.
RunResult run_pulsatile(Network&& net, const RunConfiguration& config, RunObserver& observer);

// The steady state alone (steady_run.hpp): the same folder's files, no time loop.
void run_steady(const Network& net, const RunConfiguration& config, RunObserver& observer);

}  // namespace hemotree
