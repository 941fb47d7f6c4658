#include "pulse/one_d_cut.hpp"

#include <algorithm>
#include <map>

namespace hemotree {

OneDCut one_d_cut(const NetworkBoundaries& ends, std::span<const ElementRun> blocks,
                  std::span<const std::int32_t> element_vessel, std::span<const std::int32_t> vessel_rank, int rank) {
  auto rank_of = [&](const VesselEnd& e) { return vessel_rank[static_cast<std::size_t>(e.vessel)]; };
  OneDCut cut;
  for (const ElementRun& b : blocks) {
    std::int64_t el = b.first;
    const std::int64_t end = b.first + b.count;
    while (el < end) {
      while (el < end && vessel_rank[static_cast<std::size_t>(element_vessel[static_cast<std::size_t>(el)])] != rank) ++el;
      const std::int64_t first = el;
      while (el < end && vessel_rank[static_cast<std::size_t>(element_vessel[static_cast<std::size_t>(el)])] == rank) ++el;
      if (el > first) cut.runs.push_back({b.degree, first, el - first});
    }
  }
  std::map<int, OneDCut::Neighbour> by_rank;
  const auto junctions = static_cast<std::int64_t>(ends.junction_offset.size()) - 1;
  for (std::int64_t j = 0; j < junctions; ++j) {
    const auto first = ends.junction_ends.begin() + ends.junction_offset[static_cast<std::size_t>(j)];
    const auto last = ends.junction_ends.begin() + ends.junction_offset[static_cast<std::size_t>(j) + 1];
    if (std::none_of(first, last, [&](const VesselEnd& e) { return rank_of(e) == rank; })) continue;
    cut.junctions.push_back(j);
    std::vector<int> others;
    for (auto e = first; e != last; ++e)
      if (rank_of(*e) != rank) others.push_back(rank_of(*e));
    std::sort(others.begin(), others.end());
    others.erase(std::unique(others.begin(), others.end()), others.end());
    for (const int other : others) {
      OneDCut::Neighbour& n = by_rank[other];
      n.rank = other;
      for (auto e = first; e != last; ++e) {
        if (rank_of(*e) == rank) n.send.push_back(*e);
        else if (rank_of(*e) == other) n.receive.push_back(*e);
      }
    }
  }
  for (auto& [r, n] : by_rank) cut.neighbours.push_back(std::move(n));
  return cut;
}

CouplingCut coupling_cut(const NetworkBoundaries& ends, std::span<const std::int32_t> vessel_rank,
                         std::span<const std::int32_t> node_rank, int rank) {
  std::map<int, CouplingCut::Neighbour> by_rank;
  for (std::size_t k = 0; k < ends.coupled.size(); ++k) {
    const auto& c = ends.coupled[k];
    const int end = vessel_rank[static_cast<std::size_t>(c.end.vessel)], node = node_rank[static_cast<std::size_t>(c.node)];
    if (end == node) continue;
    if (end == rank) {
      by_rank[node].rank = node;
      by_rank[node].ends.push_back(static_cast<std::int32_t>(k));
    } else if (node == rank) {
      by_rank[end].rank = end;
      by_rank[end].nodes.push_back(static_cast<std::int32_t>(k));
    }
  }
  CouplingCut cut;
  for (auto& [r, n] : by_rank) cut.neighbours.push_back(std::move(n));
  return cut;
}

}  // namespace hemotree
