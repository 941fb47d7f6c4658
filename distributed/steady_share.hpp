// A rank's share of a tree network's steady system over MPI ranks: its nodes, its vessels
// (each of its nodes' to its parent), each node's shunt and inflow from steady_rows (the
// inlet's flow added as the one-process SteadyFlowSolver adds it), and a solve with given
// resistances by the distributed elimination (distributed/mpi_tree_system.hpp) that leaves the
// pressures and flows this rank holds, each by the one-process system's arithmetic. The steady
// flow over ranks solves it once with the rigid resistances, the distended state once a sweep.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "distributed/mpi_tree_system.hpp"
#include "distributed/tree_share.hpp"
#include "formats/network.hpp"
#include "steady/steady_flow.hpp"

namespace hemotree {

class SteadyShare {
 public:
  // A node's row: its shunt to ground and the flow into it from outside (its boundary's, the
  // inlet's).
  struct Row {
    double shunt = 0, inflow = 0;
  };
  // cut: the network's (distributed/network_cut.hpp), the same on every rank; row(node): each
  // node this rank holds, asked once in nodes() order. net: the network or its topology
  // (formats/network_slice.hpp), whose ids name a refusal. A rank's set-up alone: run it
  // under on_every_rank (mpi/session.hpp).
  SteadyShare(const Network& net, const TreeCut& cut, const std::function<Row(std::int32_t node)>& row);
  // The rows of the whole network's steady_rows, the inlet's flow added at its node.
  SteadyShare(const Network& net, const TreeCut& cut, const SteadyRows& rows, double inlet_flow);

  std::span<const std::int32_t> nodes() const { return system_.nodes(); }
  std::span<const std::int32_t> vessels() const { return vessels_; }
  bool holds(std::int32_t node) const;  // one of nodes()

  // conductance: per node of nodes(), that of its edge to its parent (unread at a root of the
  // forest). The pressures of nodes(), in their order; those of its share roots' parents in
  // root_parent_pressures(), in root_parents()' order. Collective; a tree with no path to
  // ground is refused on every rank alike.
  std::span<const double> solve_nodes(std::span<const double> conductance);
  std::span<const std::int32_t> root_parents() const { return system_.root_parents(); }
  std::span<const double> root_parent_pressures() const { return system_.root_parent_potentials(); }

  // resistance: per vessel of the network, those of vessels() read. Into s (whole-network
  // arrays, sized once; other ranks' entries left as they are): the pressures of nodes() and
  // of its share roots' parents, the flows of vessels(), the inlet's pressure where this rank
  // holds the inlet's node (NaN elsewhere). Collective; a tree with no path to ground is
  // refused on every rank alike.
  void solve(const std::vector<double>& resistance, SteadyFlow& s);
  const MpiTreeSystem::Traffic& traffic() const { return system_.traffic(); }

 private:
  const Network& net_;
  const TreeCut& cut_;
  std::int64_t inlet_node_ = -1;
  MpiTreeSystem system_;
  std::vector<std::int32_t> vessels_, sorted_nodes_;
  std::vector<double> shunt_, inflow_, conductance_, x_;
};

}  // namespace hemotree
