// A network of conductances with conditions at its nodes: at some nodes the pressure is
// prescribed (Dirichlet), at the others a flow may be injected and a shunt may lead to a
// known pressure (an outlet's resistance to its outflow pressure). Kirchhoff's current law
// at every free node,
//
//   sum_e g_e (p_i - p_j) + s_i (p_i - p_s,i) = q_i,
//
// with the prescribed pressures moved to the right-hand side: each edge from a free node to a
// prescribed one is a shunt to that pressure. What remains is the nodal system of the free
// nodes (nodal_system.hpp): the tree elimination on a forest, the sparse Cholesky otherwise.
// Steady flow in any measured network (loops, several inlets and outlets, pressures and flows
// given at nodes) is this system with the vessels' Poiseuille conductances.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "network_flow/nodal_system.hpp"

namespace hemotree {

class FlowNetwork {
 public:
  // Edges a[e] -> b[e] between node indices; prescribed[i] != 0: node i's pressure is given.
  // std::invalid_argument for an edge out of range or a loop on one node.
  FlowNetwork(std::size_t nodes, std::span<const std::int32_t> a, std::span<const std::int32_t> b,
              std::span<const unsigned char> prescribed);

  std::size_t node_count() const { return nodes_; }
  std::size_t edge_count() const { return a_.size(); }
  std::size_t free_node_count() const { return system_.node_count(); }
  NodalSystem::Method method() const { return system_.method(); }

  // conductance per edge (> 0); shunt per node (>= 0, ignored at prescribed nodes). Returns
  // -1, or a free node of a part that reaches no prescribed pressure and no shunt (its
  // pressures are undetermined), its lowest.
  std::int64_t factorize(std::span<const double> conductance, std::span<const double> shunt);

  // Threads for a tree's sweeps (NodalSystem::set_threads: the same bits for any count).
  void set_threads(int threads) { system_.set_threads(threads); }

  // Node pressures from the last factorisation: inflow[i] is the flow injected into free node
  // i (flow boundaries, plus s_i p_s,i for its shunt), pressure[i] is read at the prescribed
  // nodes and written at the others.
  void solve(std::span<const double> inflow, std::span<double> pressure) const;

  // The flow of every edge, a -> b positive: g_e (p_a - p_b).
  void edge_flows(std::span<const double> pressure, std::span<double> flow) const;

 private:
  std::size_t nodes_ = 0;
  std::vector<std::int32_t> a_, b_;
  // Where no pressure is prescribed (a tree's inflow and its outlets' shunts) the free system
  // is the network itself: no index lists, and the conductances, shunts and right-hand side go
  // to it as given (on the full tree about 200 MB less to allocate and touch: its steady state
  // 2.07 -> 1.55 s, bench/README.md). Else:
  bool all_free_ = false;
  std::vector<std::int32_t> free_index_;  // per node: its row in the free system, or -1
  std::vector<std::int32_t> free_node_;   // per row: its node
  // Edges between free nodes (the system's edges, in edge order) and from a free node to a
  // prescribed one (shunts of the free node to that pressure).
  std::vector<std::int32_t> inner_edge_, boundary_edge_;
  NodalSystem system_;
  std::vector<double> conductance_;  // the last factorisation's, per edge
  std::vector<double> inner_conductance_, free_shunt_;
  mutable std::vector<double> rhs_;
};

}  // namespace hemotree
