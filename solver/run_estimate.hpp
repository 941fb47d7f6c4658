// What a run will cost, known before its first step: the steps from the time step and the
// cycles, the wall time from a cost model of a step (per element, by degree, measured on
// this project's reference machine; bench/README.md). A run whose estimate exceeds a day
// is refused unless forced: a typo in --dt or a vessel's stiffness must not start a run
// that never ends without a word.
#pragma once

#include <string>
#include <vector>

namespace hemotree {

struct RunEstimate {
  double steps = 0;    // over the whole run (a double: absurd counts must not wrap)
  double seconds = 0;  // wall time on one core of the reference machine, over threads
};

// elements_of_degree[p]: 1D elements of degree p, each step of the run substeps steps of
// theirs; lumped_vessels: 0D vessels, one implicit step per step; spread_solves: where the 0D
// vessels are spread over ranks, the solves over the ranks a step (pulse/step_cost.hpp), each
// over spread_nodes nodes a rank.
RunEstimate estimate_run(const std::vector<double>& elements_of_degree, double steps, int threads,
                         double substeps = 1, double lumped_vessels = 0, double spread_solves = 0,
                         double spread_nodes = 0);

// A red-cell or tracer transport step, per cell: measured 85 ns of wall time a cell and
// transport step on two threads, on the 421,047-vessel tree and on the full tree alike
// (bench/README.md, "Red cells and tracers over ranks"), most of it serial (the sweep in flow
// order) or the viscosity feedback's; 100 ns on any number of threads, so that the estimate
// errs long.
inline constexpr double per_transport_cell = 100e-9;  // [s per cell and transport step]

// "3.2 s", "4.1 min", "2.5 h", "3.1 days", "2e+06 years".
std::string describe_duration(double seconds);
// "284 kB", "29.5 MB", "1.23 GB" (decimal units).
std::string describe_bytes(double bytes);

}  // namespace hemotree
