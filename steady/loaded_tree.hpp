// A linear resistive network with loads (a tree, as a rule): the network's vessels
// (Poiseuille resistances) and outlets (R to ground; RCR as R1 to a capacitor node and R2 to
// ground, at the outlet's node), prescribed flows open (the inlet), prescribed pressures
// held (potential 0), and at every node and every capacitor node a conductance to ground
// and an injected current. The boundaries are the run's (formats/run_boundaries.hpp).
// Its potentials are what the slow drift of the network's compliances towards the periodic
// state needs (PulseSolver::balance_compliances): pressure shifts in Pa for volume rates in
// m^3/s. Outflow pressures are zero: the tree is the network's response to disturbances.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "formats/network.hpp"
#include "formats/run_boundaries.hpp"
#include "network_flow/nodal_system.hpp"

namespace hemotree {

struct TreeLoads {
  std::vector<double> node_shunt, node_current;            // per node [m^3/(s Pa)], [m^3/s]
  // Per run outlet (RCR only; a tree's: net.outlets); both may be empty where no outlet is RCR
  // (a tree's two million capillary outlets: 30 MB of zeros).
  std::vector<double> capacitor_shunt, capacitor_current;
};

struct TreePotentials {
  std::vector<double> node;       // per node [Pa]
  std::vector<double> capacitor;  // per run outlet: the capacitor node's (RCR), else 0 [Pa]
};

// The nodal system (network_flow/nodal_system.hpp) of the network's nodes and the RCR outlets'
// capacitor nodes (node -R1- capacitor node -R2- ground): on a tree the elimination from the
// leaves up, O(vessels); the network may have loops too (a sparse Cholesky factorisation
// then). A held node is eliminated exactly (its vessels become shunts at their other nodes).
// Throws InputError for a tree form's outlets where steady_outlets does (a terminal vessel
// without an outlet, an outlet on a vessel that is not terminal), for a reflection outlet,
// and where a part of the network has no path to ground.
TreePotentials solve_loaded_tree(const Network& net, const std::vector<double>& resistance, const TreeLoads& loads);
// The same with the network's boundary list given (a run holds one).
TreePotentials solve_loaded_tree(const Network& net, const RunBoundaries& boundaries,
                                 const std::vector<double>& resistance, const TreeLoads& loads);

// The same network and resistances for several loads (the compliance balance solves three):
// the graph, its conductances and the elimination's plan made once, each solve a
// factorisation with its loads' shunts. The network and the boundaries must outlive it.
class LoadedTree {
 public:
  LoadedTree(const Network& net, const RunBoundaries& boundaries, const std::vector<double>& resistance);
  TreePotentials solve(const TreeLoads& loads);

 private:
  // Run outlet k's parameters and its node.
  const Outlet& outlet(std::size_t k) const { return boundaries_.outlet(static_cast<std::size_t>(outlet_boundary_[k])); }
  std::int32_t outlet_node(std::size_t k) const { return boundaries_.node(static_cast<std::size_t>(outlet_boundary_[k])); }
  const Network& net_;
  const RunBoundaries& boundaries_;
  std::vector<std::int32_t> outlet_boundary_;  // per run outlet: its place in the boundaries
  std::vector<std::int32_t> capacitor_node_;   // per run outlet: its capacitor's node, or -1
  bool rcr_outlets_ = false;                   // whether any outlet is RCR (capacitor loads read)
  std::vector<double> conductance_;            // per edge of system_
  // Shunts added whatever the loads: a vessel to a held node, at its other node; nodes held
  // at 0 (a prescribed pressure, or no vessel there).
  std::vector<std::pair<std::int32_t, double>> held_end_shunt_;
  std::vector<std::int32_t> grounded_, untouched_;
  NodalSystem system_;
};

}  // namespace hemotree
