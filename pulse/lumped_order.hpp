// The order the 0D vessels and their nodes are kept in (pulse/lumped_vessels). The
// elimination's parallel sweeps (network_flow/nodal_system) take subtrees as tasks; in the
// network's own order (vgen's is breadth first) a task's nodes lie in short runs on every
// level of the tree, and two threads swept slower than one (measured, 1 M vessels). On a
// forest the subtree order keeps each task's nodes together, in the network's order, at the
// place of the task's root; the nodes above the tasks keep their places, and each vessel
// goes with the node it leads to from its tree's root.
//
// Where the network's order joins every node to one lower node (a network numbered from its
// root) the elimination is the same in both orders: the same root, the same parent of every
// node, siblings and every node's vessels in the same order; so the same pivots and sums, bit
// for bit (tests/test_lumped_order).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "formats/network.hpp"

namespace hemotree {

struct LumpedOrder {
  std::vector<std::int32_t> vessels;  // network vessel indices of the 0D vessels, in order
  std::vector<std::int32_t> nodes;    // network node indices of their nodes, in order
};

// The network's order of the nodes of the given vessels (their `from` and `to` nodes, in
// from[v], to[v] order of each): each node at its first appearance. The one definition of the
// network's order, for the network's arrays and for the 0D vessels' own (their checkpoint).
std::vector<std::int32_t> nodes_by_first_appearance(std::span<const std::int32_t> vessels,
                                                    std::span<const std::int32_t> from,
                                                    std::span<const std::int32_t> to, std::size_t nodes);

// The network's order: the 0D vessels as it lists them, their nodes by first appearance.
LumpedOrder network_lumped_order(const Network& net, const std::vector<bool>& zero_d);
// The subtree order above; the network's below NodalSystem's task threshold, or where the 0D
// vessels form a graph with a loop.
LumpedOrder subtree_lumped_order(const Network& net, const std::vector<bool>& zero_d);
// The vessels of `order` that `keep` marks and their nodes, each in the order's own order: a
// share's 0D vessels as the whole run numbers them, so that every sum it takes at a node runs
// in the whole's order (docs/scaling.md, the plan of the pulsatile run over ranks).
LumpedOrder restrict_order(const LumpedOrder& order, const Network& net, const std::vector<bool>& keep);

// The places of the 0D state in a checkpoint (LumpedVessels::save), of the whole run with one
// pi section a vessel: its nodes in the network's order (network_lumped_order), then one
// capacitor node per RCR outlet at them (in the run's outlet order); its edges, the 0D vessels
// in the network's order, then the capacitors' R1 edges. What a rank of a run over ranks needs
// to put its share where the whole run would (every rank computes them alike), so that a
// checkpoint is the one-process run's, bytes and all, and any rank count resumes it.
struct LumpedPlaces {
  std::vector<std::int32_t> node;       // per network node: its place (-1: no 0D vessel's)
  std::vector<std::int32_t> vessel;     // per network vessel: its edge's place (-1: 1D)
  std::vector<std::int32_t> capacitor;  // per outlet: its capacitor node's place (-1: none)
  std::vector<std::int32_t> r1_edge;    // per outlet: its R1 edge's place (-1: none)
  std::size_t nodes = 0, edges = 0;     // of the whole run
};
LumpedPlaces lumped_places(const Network& net, const std::vector<bool>& zero_d);

}  // namespace hemotree
