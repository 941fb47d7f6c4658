// The steady flow and red-cell distribution consistent with each other
// (steady/steady_hematocrit.hpp's solve_steady_with_phase_separation) over the ranks of the
// MPI session: each pass's flow solve over the ranks (distributed/steady_over_ranks.hpp, the
// one-process solve's bits on a tree), the hematocrits distributed in flow order on rank 0,
// which holds the whole flow, and the relaxed hematocrits sent to every rank for the next
// pass's resistances. Collective.
#pragma once

#include <functional>
#include <optional>
#include <string>

#include "physics/blood.hpp"
#include "formats/network.hpp"
#include "steady/steady_hematocrit.hpp"

namespace hemotree {

struct SteadyHematocritOverRanks {
  SteadyHematocritResult result;  // on rank 0 (its iterations, convergence and change on every rank)
  std::string partition;          // the last flow solve's partition in one line
};

// The one-process iteration's settings, checks and refusals (InputError, on every rank alike).
SteadyHematocritOverRanks solve_steady_with_phase_separation_over_ranks(const Network& net, const Blood& blood,
                                                                        int max_iterations, double tolerance,
                                                                        double relaxation);

// The same with each rank but rank 0 holding only its slice of the network
// (distributed/steady_on_slices.hpp): held and path as SteadyFlowOnSlices takes them; each
// pass's hematocrits sent to each rank for its slice's vessels alone. None, on every rank
// alike, where the slices do not serve the network: the caller then solves it whole.
std::optional<SteadyHematocritOverRanks> solve_steady_with_phase_separation_on_slices(
    const Network& held, const std::string& path, const std::function<Blood(const Network&)>& blood_of,
    int max_iterations, double tolerance, double relaxation);

}  // namespace hemotree
