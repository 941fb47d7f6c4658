// Steady red-cell distribution of a network: the discharge hematocrit of every vessel from its
// flows (mixing at nodes, Pries-Secomb phase separation at diverging bifurcations, as in
// Secomb's NetFlow dishem.cpp), and the steady flow coupled to it through the viscosity law
// (each vessel's apparent viscosity at its own hematocrit), solved by under-relaxed fixed-point
// iteration. Issue 14; the laws: physics/phase_separation.hpp, docs/physics.md.
#pragma once

#include <span>
#include <vector>

#include "formats/network.hpp"
#include "steady/steady_flow.hpp"

namespace hemotree {

// The discharge hematocrit of every vessel for the signed flows `flow` (per vessel, positive
// from -> to [m^3/s]). Nodes are visited in a topological order of the directed graph the flows
// define; at each node the blood entering it (from upstream vessels and, where the vessels'
// flows leave a surplus, from the node's boundary, at its hematocrit, NaN = default_hematocrit)
// is distributed to the vessels leaving it:
//   - a node with exactly one inflowing vessel, two outflowing vessels and no boundary (a
//     diverging bifurcation, NetFlow's nodtyp 3): the phase-separation law with that vessel as
//     the feed (D_F its diameter at the node), FQB the first daughter's share of the outflow,
//     diameter_scale passed to the law (1 reproduces NetFlow);
//   - every other node (converging nodes, a node with a boundary, several inflows feeding two
//     vessels, one vessel feeding more than two): every outflow takes the flux-weighted mix
//     H = sum Q_i H_i / sum Q_i of the inflows (NetFlow's rule for nodes of more than three
//     segments; no separation); flow leaving through a boundary takes the mix too.
// A vessel with zero flow carries plasma only, 0: the law's limit as a daughter's flow vanishes
// (plasma skimming) and no red cells are lost from the nodes' balance. Red cells are conserved
// at every node to round-off. Throws InputError for spans of the wrong length, a non-finite
// flow, a directed cycle of flows (naming a vessel on it; Poiseuille flows, being driven by
// pressure differences, have none) or where the laws refuse (a hematocrit reaching 1, a feed
// too narrow for the law), naming the node.
std::vector<double> distribute_hematocrit(const Network& net, std::span<const double> flow,
                                          double default_hematocrit, double diameter_scale);

struct SteadyHematocritResult {
  SteadyFlow flow;                  // the flows with every vessel's viscosity at `hematocrit`
  std::vector<double> hematocrit;   // discharge hematocrit per vessel, distribute_hematocrit(flow)
  int iterations = 0;               // flow solves done
  bool converged = false;           // the last change was below the tolerance
  double change = 0;                // the last change (see below)
};

// The steady flow and hematocrits consistent with each other: starting from the blood's
// hematocrit in every vessel, repeat
//   flows from Poiseuille resistances with each vessel's apparent viscosity at its own
//     hematocrit (apparent_viscosity with Blood::hematocrit set to it: Pries with the cell-size
//     diameter scale and pries_max_diameter, or Newtonian);
//   target hematocrits from those flows (distribute_hematocrit, phase separation with
//     diameter_scale 1 as NetFlow's dishem.cpp);
//   change = the largest of |target - H| over vessels and |Q - Q_previous| / max |Q|;
//   H += relaxation (target - H);
// until change < tolerance or max_iterations flow solves. The flows are then those of the
// hematocrits before the last relaxation, and `hematocrit` is recomputed from them, so the
// result obeys the hematocrit rules exactly and the flow equations to within `change`.
// converged says whether the tolerance was met; an unconverged result is returned as such.
// Relaxation: the rat mesentery (1130 vessels) oscillates at 1 (no convergence in 2000 passes)
// and converges to 1e-10 in 59 passes at 0.5, 144 at 0.2; its flows and hematocrits then
// agree with NetFlow's own solution to the 6 digits NetFlow writes (median 4e-7 relative).
// The inflow at a tree inlet is its mean. Throws InputError for max_iterations < 1, tolerance
// <= 0, relaxation outside (0, 1], and where solve_steady_flow or distribute_hematocrit does.
SteadyHematocritResult solve_steady_with_phase_separation(const Network& net, const Blood& blood,
                                                          int max_iterations, double tolerance,
                                                          double relaxation);

// The iteration's checks of its settings (InputError, as above).
void check_phase_separation_settings(int max_iterations, double tolerance, double relaxation);

// One pass of that iteration after its flow solve s (of the resistances at hematocrits h):
// the round-off flows set to zero in s, the target hematocrits from the flows and the change
// against h and the previous pass's flows (empty: the first pass, the change infinite). What a
// run over ranks takes on rank 0 (distributed/steady_hematocrit_over_ranks.hpp).
struct HematocritPass {
  std::vector<double> target;
  double change = 0;
};
HematocritPass hematocrit_pass(const Network& net, const Blood& blood, SteadyFlow& s, std::span<const double> h,
                               std::span<const double> previous_flow);

}  // namespace hemotree
