// The order the 0D vessels and their nodes are kept in (pulse/lumped_vessels): on a forest,
// each tree's nodes in depth-first preorder from its lowest node and each vessel at its
// lower-end node's place, so that every subtree occupies one contiguous range of the arrays.
// The elimination's parallel sweeps (network_flow/nodal_system) take subtrees as tasks: in
// the network's own order (vgen's is breadth first) a subtree's nodes lie scattered over
// every level of the tree, and two threads swept slower than one (measured, 1M vessels).
//
// The elimination is the same as in the network's order wherever that joins every node to
// one lower node (a network numbered from its root): the same root, the same parent of every
// node, siblings in the same order, every node's vessels in the same order; so the same
// pivots and sums, bit for bit. A graph with a loop keeps the network's order.
#pragma once

#include <cstdint>
#include <vector>

#include "formats/network.hpp"

namespace hemotree {

struct LumpedOrder {
  std::vector<std::int32_t> vessels;  // network vessel indices of the 0D vessels, in order
  std::vector<std::int64_t> nodes;    // network node indices of their nodes, in order
};

// The network's order: the 0D vessels as it lists them, their nodes as they first appear
// (each vessel's `from`, then its `to`).
LumpedOrder network_lumped_order(const Network& net, const std::vector<bool>& zero_d);
// The order above, or the network's where the 0D vessels form a graph with a loop.
LumpedOrder subtree_lumped_order(const Network& net, const std::vector<bool>& zero_d);

}  // namespace hemotree
