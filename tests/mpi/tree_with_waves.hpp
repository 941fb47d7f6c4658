// The network and the solver options of the MPI tests of the pulsatile run over ranks
// (pulse_step, cycle_statistics): vgen --seed 3 --root-diameter 1mm --min-diameter 50um |
// vprune --budget all, in code (9,245 vessels, the paper's half-sine inflow of 1.74 ml/min,
// outlets calibrated), run with --model auto, one pi section a 0D vessel (as over ranks) and
// the steady start: 83 vessels 1D.
#pragma once

#include <bit>
#include <cstdint>

#include "../grown_trees.hpp"
#include "pruner/outlet_calibration.hpp"
#include "pruner/pruning_strategies.hpp"
#include "pulse/pulse_solver.hpp"

namespace hemotree::test_networks {

// (A larger min_diameter: a smaller tree of the same rules, 79 vessels at 250 um.)
inline Network tree_with_waves(double min_diameter = 50e-6) {
  Network full = grown_tree(1e-3, min_diameter, 3);
  full.blood = Blood{};
  Inlet inlet;
  inlet.vessel = full.id[0];
  inlet.waveform.mean = 1.74e-6 / 60;
  full.inlet = inlet;
  const KeepMask keep(full.vessel_count(), 1);
  Network net = extract(full, keep);
  calibrate_outlets(full, keep, net, OutletParameters{});
  return net;
}

inline SolverOptions options_over_ranks() {
  SolverOptions options;
  options.model = ModelChoice::automatic;
  options.lumped_sections = 1;
  options.start = StartChoice::steady;
  return options;
}

inline bool same_bits(double a, double b) { return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b); }

}  // namespace hemotree::test_networks
