// The common case of a forest's elimination order, at the cost of one pass over the edges:
// where every node has at most one edge to a node of a lower label (a tree labelled from its
// root depth-first, as vgen and vprune write theirs), each node hangs from that lower node,
// the lowest node of each component is its root (the largest label on a cycle would have two
// lower neighbours), and the labels in their own order put every parent before its children.
// Both nodal systems' sweeps then stream through memory (nodal_system, harmonic_system).
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

}  // namespace hemotree
