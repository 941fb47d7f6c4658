// The distended steady state's fixed-point iteration (solve_distended_steady_flow,
// steady/steady_flow.hpp) over the part of a network one process holds: the whole network, or
// a rank's share of one solved over MPI ranks (distributed/distended_over_ranks.hpp). Each
// vessel's resistance is its own arithmetic and the sweep's decisions rest on maxima (the
// largest change of a node's pressure, the scale), exact in any order, so every split sweeps
// alike and gives the same bits.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "formats/network.hpp"
#include "physics/blood.hpp"
#include "physics/tube_law.hpp"
#include "physics/viscosity_table.hpp"
#include "steady/steady_flow.hpp"

namespace hemotree {

struct DistendedPart {
  std::span<const std::int32_t> vessels;  // whose resistances this process updates (empty: every one)
  std::span<const std::int32_t> nodes;    // whose pressures it holds (empty: every one)
  // The linear solve with resistances r (those of `vessels` read) into s: the pressures of
  // `nodes` and of every node of `vessels`, the flows of `vessels`, the inlet's pressure where
  // this process holds the inlet's node (NaN elsewhere).
  std::function<void(const std::vector<double>& r, SteadyFlow& s)> solve;
  // The largest of every process's number, NaN counting as none (on one process: itself).
  std::function<double(double)> largest;
  // Runs a step every process takes and makes its failure every process's (on one: the step).
  std::function<void(const std::function<void()>&)> on_every_part;
};

// r: per vessel of the network, those of `vessels` the first resistances (the rigid ones) in,
// the last ones out. Throws InputError where a lumen collapses (the lowest vessel's message
// within a part). threads: the resistances in parallel blocks (the same numbers for any count).
SteadyFlow iterate_distended(const Network& net, const Blood& blood, std::span<const TubeLaw> laws,
                             const ViscosityTable& viscosity, const DistendedPart& part, std::vector<double>& r,
                             int threads);

}  // namespace hemotree
