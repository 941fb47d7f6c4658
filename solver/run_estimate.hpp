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
// theirs; lumped_vessels: 0D vessels, one implicit step per step.
RunEstimate estimate_run(const std::vector<double>& elements_of_degree, double steps, int threads,
                         double substeps = 1, double lumped_vessels = 0);

// "3.2 s", "4.1 min", "2.5 h", "3.1 days", "2e+06 years".
std::string describe_duration(double seconds);

}  // namespace hemotree
