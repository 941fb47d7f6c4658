// The distended steady state (steady/steady_flow.hpp's solve_distended_steady_flow: every
// vessel at the lumen of its mean pressure) of a tree network over the ranks of the MPI
// session: the iteration of steady/distended_iteration.hpp with each rank's share (its
// vessels, its nodes) and the distributed elimination (distributed/mpi_tree_system.hpp) for
// each sweep's solve. Each rank ends with its share's part of the one-process result, bit
// for bit, for any number of ranks: what a pulsatile run over ranks starts from. Collective.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "distributed/mpi_tree_system.hpp"
#include "distributed/tree_share.hpp"
#include "formats/network.hpp"
#include "physics/blood.hpp"
#include "physics/tube_law.hpp"
#include "physics/viscosity_table.hpp"
#include "steady/steady_flow.hpp"

namespace hemotree {

struct DistendedOverRanks {
  std::vector<std::int32_t> vessels, nodes;  // this rank's: its nodes' vessels to their parents, its nodes
  std::vector<std::int32_t> nodes_by_label;  // its nodes in increasing labels
  // Per vessel and per node of the network, this rank's entries set: the pressures of its nodes
  // and of its share roots' parents, the flows and the last resistances of its vessels (the
  // rest 0); the inlet's pressure where this rank holds the inlet's node (NaN elsewhere).
  SteadyFlow flow;
  std::vector<double> resistance;
  int sweeps = 0;  // the linear solves it took
  MpiTreeSystem::Traffic traffic;  // this rank's exchanges in them
};

// cut: the network's (distributed/network_cut.hpp), the same on every rank. InputError where
// a lumen collapses or the tree has no path to ground, on every rank alike.
DistendedOverRanks solve_distended_steady_flow_over_ranks(const Network& net, const TreeCut& cut, const Blood& blood,
                                                         std::span<const TubeLaw> laws, const ViscosityTable& viscosity,
                                                         double inlet_flow, int threads = 1);

}  // namespace hemotree
