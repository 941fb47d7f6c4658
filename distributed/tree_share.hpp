// A forest's nodal system (network_flow/nodal_system.hpp) cut for P ranks: each rank holds a
// share, whole subtrees (the partition's pieces, partition/), and one rank also the top, the
// nodes above them. One elimination and solve in three moves, one message each way:
//
//   1. each rank eliminates its share from the leaves up to its subtrees' roots (open roots:
//      NodalSystem keeps each root's subtree conductance S_r and forward right-hand side y_r)
//      and sends, per root r, (g_r, S_r, y_r), g_r the conductance of r's edge into the top;
//   2. the top's rank eliminates the top with every share root a leaf of shunt S_r and
//      right-hand side y_r: leaf r adds g_r S_r / (g_r + S_r) and its divider times y_r to its
//      parent, the very terms, in the very order, of the whole forest's sweep; it solves the
//      top and answers each share root with its potential x_r;
//   3. each rank sweeps its share down from its roots' potentials.
//
// Every system here numbers its nodes by their place in the whole forest's elimination order
// (TreeCut::order, NodalSystem's own), so every pivot sums its children's terms in the order of
// the whole forest's sweep, and the potentials are the whole system's bit for bit, for any
// number of ranks (tests/test_tree_share.cpp). Only arithmetic here: the messages' transport is
// the caller's (distributed/mpi_tree_system.hpp), so that one process can play every rank.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "network_flow/nodal_system.hpp"

namespace hemotree {

// Where every node of a forest lies: on a rank's share or on the top. Every rank builds the
// same one.
struct TreeCut {
  static constexpr std::int32_t top = -1;
  // The forest of `nodes` nodes and edges (a[e], b[e]), each edge's owner its rank in
  // [0, ranks) or top (a partition's vessels: partition/). A node lies where the edge to its
  // parent does, a root on the top. A share must be whole subtrees: a node of a share hangs
  // from a node of the same share or of the top, and a node of the top from the top
  // (std::invalid_argument otherwise, naming the node, as for a graph that is not a forest).
  TreeCut(std::size_t nodes, std::span<const std::int32_t> a, std::span<const std::int32_t> b,
          std::span<const std::int32_t> edge_owner, int ranks, int top_rank);

  int ranks = 1, top_rank = 0;
  std::vector<std::int32_t> owner;  // per node: its rank, or top
  // The whole forest's elimination order, roots first (NodalSystem's: the labels' own where
  // every node hangs from a lower one, else peeled leaves reversed); each node's place in it,
  // its parent and the edge to it (-1 at roots).
  std::vector<std::int32_t> order, place, parent, parent_edge;
  // Per rank, its share's roots in elimination order: the nodes whose parent is on the top
  // (every root of the forest is on the top). The top's rank receives their (g, S, y) in rank
  // order, then this order.
  std::vector<std::vector<std::int32_t>> roots;
  std::vector<std::int32_t> share_nodes(int rank) const;  // in elimination order
  std::vector<std::int32_t> top_nodes() const;            // in elimination order
  // Every rank's nodes as it holds them over MPI (distributed/mpi_tree_system.hpp): its
  // share's, then on the top's rank the top's; in one pass.
  std::vector<std::vector<std::int32_t>> held_nodes() const;
  // Per edge, the rank that holds it: its lower node's (the top's rank for the top's edges).
  std::vector<std::int32_t> edge_ranks() const;
};

// Some of a cut forest's nodes as a forest of their own: a share's, or the top's with every
// share root (TreeCut::top_places). Each node's place is its rank among them in the whole
// forest's elimination order, so every system built on these places eliminates in the whole
// forest's order: its edges (a[e], b[e]) run from a parent's place to its child's.
struct CutForest {
  std::vector<std::int32_t> nodes;         // per place, the forest's node
  std::vector<std::int32_t> a, b;          // per edge: its parent's place, its child's
  std::vector<std::int32_t> parent_place;  // per place: its parent's, -1 where that is not among them
};
// nodes: a subsequence of cut.order.
CutForest cut_forest(const TreeCut& cut, std::vector<std::int32_t> nodes);
// The top's system: its own nodes and every share's roots, merged in elimination order; the
// places of the own nodes (in top_nodes() order) and of the roots (rank after rank, each
// rank's in TreeCut::roots order: the messages' slots).
struct TopPlaces {
  CutForest forest;
  std::vector<std::int32_t> own, root_place;
};
TopPlaces top_places(const TreeCut& cut);

// One rank's share. Its arrays run over share_nodes(rank), in that order: per node the
// conductance of its edge to its parent (a root's: of its edge into the top), its shunt, its
// right-hand side.
class TreeShare {
 public:
  TreeShare(const TreeCut& cut, int rank);
  std::size_t node_count() const { return nodes_.size(); }
  std::size_t root_count() const { return roots_.size(); }

  // Move 1: eliminates the share and forms y's forward half in place; the message for the
  // top, (g_r, S_r, y_r) per root. Bad conductances or shunts: NodalSystem's
  // std::invalid_argument (edges numbered by the share's non-root nodes).
  std::vector<double> factorize_forward(std::span<const double> conductance, std::span<const double> shunt,
                                        std::span<double> y);
  // Move 1 of a solve with the last factorisation: y's forward half; the message y_r per root.
  std::vector<double> forward(std::span<double> y) const;
  // Move 3: the potentials from the roots' (the top's answer, per root) and y's forward half.
  void backward(std::span<const double> root_potential, std::span<double> y) const;

 private:
  std::vector<std::int32_t> nodes_;       // global node per local place
  std::vector<std::int32_t> roots_;       // local places of the roots
  std::vector<std::int32_t> edge_place_;  // per local edge, the local place of the node below it
  std::vector<double> edge_conductance_;  // scratch: per local edge
  NodalSystem system_;
};

// The top: its own nodes and every share's roots as leaves. Its arrays run over top_nodes()
// as the share's do; messages and answers over every rank's roots, rank after rank.
class TreeTop {
 public:
  explicit TreeTop(const TreeCut& cut);
  std::size_t node_count() const { return places_.own.size(); }
  std::size_t root_count() const { return places_.root_place.size(); }

  // Move 2 after every share's factorize_forward: eliminates the top, solves it (x: the top's
  // own potentials; answer: each share root's) and returns -1, or where the forest is
  // singular (a component with no path to ground), that component's lowest node, as the
  // whole forest's NodalSystem names it.
  std::int64_t factorize_solve(std::span<const double> conductance, std::span<const double> shunt,
                               std::span<const double> b, std::span<const double> messages, std::span<double> x,
                               std::span<double> answer);
  // Move 2 after every share's forward: the same solve with the last factorisation.
  void solve(std::span<const double> b, std::span<const double> messages, std::span<double> x,
             std::span<double> answer);

 private:
  TopPlaces places_;
  std::vector<double> edge_conductance_, shunt_, y_;  // scratch: per edge, per place
  std::vector<std::int32_t> lowest_;  // per place: the lowest node it stands for (itself; a root: its subtree's)
  NodalSystem system_;
  // y_ (and where given, shunt_ and edge_conductance_) from the top's own numbers and the
  // messages (one root's numbers every `stride` of them: g, S, y or y alone).
  void gather(std::span<const double> b, std::span<const double> messages, std::size_t stride,
              std::span<const double> conductance, std::span<const double> shunt);
  void solve_and_scatter(std::span<double> x, std::span<double> answer);
};

}  // namespace hemotree
