// A forest's harmonic system (network_flow/harmonic_system.hpp: complex two-ports, not
// symmetric where a mean flow runs) cut for P ranks as distributed/tree_share.hpp cuts the
// real one, in the same three moves:
//
//   1. each rank sums its share's diagonals and eliminates the share from the leaves up to
//      its roots (HarmonicSystem with open roots), and sends, per root r, its edge into the
//      top (the entries m_rp, m_pr and the edge's term in the parent's diagonal) and its
//      pivot d_r and current y_r;
//   2. the top's rank sums the top's diagonals with those edge terms, eliminates the top with
//      every share root a leaf of pivot d_r and current y_r, solves, and answers each root
//      with its potential x_r;
//   3. each rank substitutes its share down from its roots' potentials.
//
// The whole system sums each node's diagonal from its shunt and then the terms of the edges
// at it in the order of their numbers, and eliminates in the forest's order; here every
// system numbers its nodes by their place in that order (TreeCut, CutForest) and sums every
// diagonal in the edges' order, so the potentials are the whole system's bit for bit for any
// number of ranks (tests/test_tree_share.cpp). A TreeCut of the harmonic system's own edges
// (those between free nodes) gives the numbers: an edge's number is its place in a and b.
// Only arithmetic here; one process may play every rank.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "distributed/tree_share.hpp"
#include "network_flow/harmonic_system.hpp"

namespace hemotree {

// The edge from a node up to its parent as the nodal rows see it: its terms in the node's and
// the parent's diagonals, and m_ip (the node's row, the parent's column) and m_pi.
struct EdgeToParent {
  Complex own, parent, up, down;
  // The edge's two-port between its nodes a and b, seen from the child, a or b.
  static EdgeToParent of(const TwoPort& y, bool child_is_a) {
    return child_is_a ? EdgeToParent{y.aa, y.bb, y.ab, y.ba} : EdgeToParent{y.bb, y.aa, y.ba, y.ab};
  }
};

// One rank's share: its arrays run over TreeCut::share_nodes(rank), in that order.
class HarmonicTreeShare {
 public:
  static constexpr std::size_t message_size = 5;  // per root: up, down, parent, d_r, y_r

  HarmonicTreeShare(const TreeCut& cut, int rank);
  std::size_t node_count() const { return forest_.nodes.size(); }
  std::size_t root_count() const { return roots_.size(); }

  // Move 1. Per node: its shunt (the diagonal before any edge's term: its boundaries'), its
  // current (overwritten with the forward half), and its edge to its parent (every node of a
  // share has one; a root's runs into the top). Returns the top's message, message_size
  // numbers per root in TreeCut::roots order. A zero pivot: HarmonicSystem's
  // std::invalid_argument, naming the forest's node.
  std::vector<Complex> eliminate(std::span<const Complex> shunt, std::span<const EdgeToParent> edge,
                                 std::span<Complex> current);
  // Move 3: the potentials, into current, from the roots' (the top's answer) and the forward half.
  void substitute(std::span<const Complex> root_potential, std::span<Complex> current) const;

 private:
  CutForest forest_;
  std::vector<std::int32_t> roots_;        // the places of the roots, in TreeCut::roots order
  std::vector<std::int32_t> by_edge_;      // the places, by the number of their edge to the parent
  std::vector<Complex> pivot_;             // the diagonals, then the pivots' reciprocals (roots: d_r)
  std::vector<HarmonicSystem::Coupling> coupling_;  // per edge of forest_: (m_pi, m_ip)
  HarmonicSystem system_;
};

// The top: its own nodes and every share's roots as leaves. Its arrays run over
// TreeCut::top_nodes(); messages and answers over every rank's roots, rank after rank.
class HarmonicTreeTop {
 public:
  explicit HarmonicTreeTop(const TreeCut& cut);
  std::size_t node_count() const { return places_.own.size(); }
  std::size_t root_count() const { return places_.root_place.size(); }

  // Move 2. Per own node its shunt, current and edge to its parent (unread at a root of the
  // forest); the shares' messages. x: the own nodes' potentials; answer: each share root's.
  // A zero pivot: HarmonicSystem's std::invalid_argument, naming the forest's node.
  void solve(std::span<const Complex> shunt, std::span<const Complex> current, std::span<const EdgeToParent> edge,
             std::span<const Complex> messages, std::span<Complex> x, std::span<Complex> answer);

 private:
  TopPlaces places_;
  // The top's edges by their numbers: the place below each, and the own node (>= 0) or the
  // root's message slot (~slot) that describes it.
  std::vector<std::int32_t> edge_below_, edge_source_;
  std::vector<Complex> pivot_, x_;
  std::vector<HarmonicSystem::Coupling> coupling_;  // per edge of places_.forest
  std::vector<std::int32_t> edge_of_place_;         // per place, its edge in places_.forest (-1: none)
  HarmonicSystem system_;
};

}  // namespace hemotree
