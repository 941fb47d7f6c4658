// A forest's elimination order, for both nodal systems' tree eliminations (nodal_system,
// harmonic_system): every node after its children, so that the leaves-up sweep finds each
// node's pivot final when it reaches it.
//
// The common case at the cost of one pass over the edges (parents_below): where every node
// has at most one edge to a node of a lower label (a tree labelled from its root depth-first,
// as vgen and vprune write theirs), each node hangs from that lower node, the lowest node of
// each component is its root (the largest label on a cycle would have two lower neighbours),
// and the labels in their own order put every parent before its children: the sweeps then
// stream through memory. Any other forest by peeling leaves (peel_leaves).
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

namespace hemotree {

// parent_edge[c]: the edge from node c to its lower neighbour, -1 at a root. False where a
// node has two lower neighbours (parent_edge then unspecified).
inline bool parents_below(std::size_t nodes, std::span<const std::int32_t> a, std::span<const std::int32_t> b,
                          std::vector<std::int32_t>& parent_edge) {
  parent_edge.assign(nodes, -1);
  for (std::size_t e = 0; e < a.size(); ++e) {
    const auto child = static_cast<std::size_t>(std::max(a[e], b[e]));
    if (parent_edge[child] >= 0) return false;
    parent_edge[child] = static_cast<std::int32_t>(e);
  }
  return true;
}

// Peeling leaves: a node with one edge left hangs from that edge's other node, and removing
// it may make that one a leaf in turn; the last node of each component is its root. order:
// the nodes as peeled (leaves first, every node after its children), parent[c] and
// parent_edge[c] (-1 at a root). They first hold the XOR of each node's remaining neighbours
// and edges, so that a leaf's one neighbour and edge are there to read without an adjacency
// list (O(nodes), three flat arrays). False where the graph is not a forest: nodes on a loop
// or a doubled edge are never peeled (the arrays then unspecified).
inline bool peel_leaves(std::size_t nodes, std::span<const std::int32_t> a, std::span<const std::int32_t> b,
                        std::vector<std::int32_t>& order, std::vector<std::int32_t>& parent,
                        std::vector<std::int32_t>& parent_edge) {
  std::vector<std::int32_t> degree(nodes, 0);
  parent.assign(nodes, 0);
  parent_edge.assign(nodes, 0);
  for (std::size_t e = 0; e < a.size(); ++e) {
    const auto ea = static_cast<std::size_t>(a[e]), eb = static_cast<std::size_t>(b[e]);
    ++degree[ea];
    ++degree[eb];
    parent[ea] ^= b[e];
    parent[eb] ^= a[e];
    parent_edge[ea] ^= static_cast<std::int32_t>(e);
    parent_edge[eb] ^= static_cast<std::int32_t>(e);
  }
  order.clear();
  order.reserve(nodes);
  for (std::size_t i = 0; i < nodes; ++i)
    if (degree[i] <= 1) order.push_back(static_cast<std::int32_t>(i));
  for (std::size_t head = 0; head < order.size(); ++head) {
    const auto c = static_cast<std::size_t>(order[head]);
    if (degree[c] == 0) {  // the last of its component
      parent[c] = parent_edge[c] = -1;
      continue;
    }
    degree[c] = 0;
    const auto p = static_cast<std::size_t>(parent[c]);
    parent[p] ^= static_cast<std::int32_t>(c);
    parent_edge[p] ^= parent_edge[c];
    if (--degree[p] == 1) order.push_back(static_cast<std::int32_t>(p));
  }
  return order.size() == nodes;
}

}  // namespace hemotree
