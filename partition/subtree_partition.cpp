// Whole subtrees to each rank (partition/partition.hpp): split from the top, largest first,
// then dealt largest first to the least loaded rank.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <queue>
#include <utility>
#include <vector>

#include "formats/topology.hpp"
#include "partition/partition_methods.hpp"

namespace hemotree {

namespace {

// Roots first: vessels whose `from` node no vessel enters.
std::vector<std::int32_t> root_vessels(const Network& net) {
  std::vector<std::uint8_t> entered(net.node_count(), 0);
  for (std::size_t v = 0; v < net.vessel_count(); ++v) entered[static_cast<std::size_t>(net.to[v])] = 1;
  std::vector<std::int32_t> roots;
  for (std::size_t v = 0; v < net.vessel_count(); ++v)
    if (!entered[static_cast<std::size_t>(net.from[v])]) roots.push_back(static_cast<std::int32_t>(v));
  return roots;
}

// Every vessel of the forest, each parent before its daughters.
std::vector<std::int32_t> downstream_order(const Children& children, const std::vector<std::int32_t>& roots) {
  std::vector<std::int32_t> order(roots);
  order.reserve(children.offset.size() - 1);
  for (std::size_t k = 0; k < order.size(); ++k) {
    const auto v = static_cast<std::size_t>(order[k]);
    for (std::int64_t c = children.offset[v]; c < children.offset[v + 1]; ++c) order.push_back(children.index[c]);
  }
  return order;
}

}  // namespace

bool is_forest(const Network& net) {
  std::vector<std::uint8_t> entered(net.node_count(), 0);
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    auto& e = entered[static_cast<std::size_t>(net.to[v])];
    if (e) return false;
    e = 1;
  }
  // With in-degrees at most one, a vessel not reached from a root lies on a directed cycle.
  return downstream_order(children_of(net), root_vessels(net)).size() == net.vessel_count();
}

namespace {

// The forest cut into pieces: the subtrees of `pieces` (their roots) and the vessels above
// them, the top.
struct Cut {
  std::vector<std::int32_t> pieces, top;
  double top_cost = 0;
};

// The pieces (and the top, as one piece) dealt largest first, each to the least loaded rank
// (the lowest of equals): each piece's rank, the top's last; the largest load.
std::pair<std::vector<std::int32_t>, double> deal(const Cut& cut, const std::vector<double>& subtree, int ranks) {
  std::vector<std::pair<double, std::size_t>> by_cost;  // (cost, piece; the top is pieces.size())
  by_cost.reserve(cut.pieces.size() + 1);
  for (std::size_t k = 0; k < cut.pieces.size(); ++k)
    by_cost.emplace_back(subtree[static_cast<std::size_t>(cut.pieces[k])], k);
  if (!cut.top.empty()) by_cost.emplace_back(cut.top_cost, cut.pieces.size());
  std::stable_sort(by_cost.begin(), by_cost.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<double> load(static_cast<std::size_t>(ranks), 0.0);
  std::vector<std::int32_t> rank(cut.pieces.size() + 1, 0);
  for (const auto& [c, k] : by_cost) {
    const auto r = static_cast<std::size_t>(std::min_element(load.begin(), load.end()) - load.begin());
    load[r] += c;
    rank[k] = static_cast<std::int32_t>(r);
  }
  return {rank, *std::max_element(load.begin(), load.end())};
}

}  // namespace

Partition partition_subtrees(const Network& net, std::span<const double> cost, int ranks) {
  const std::size_t n = net.vessel_count();
  const Children children = children_of(net);
  const std::vector<std::int32_t> roots = root_vessels(net);
  const std::vector<std::int32_t> order = downstream_order(children, roots);
  // The cost of each vessel's subtree, daughters before parents.
  std::vector<double> subtree(cost.begin(), cost.end());
  for (std::size_t k = n; k-- > 0;) {
    const auto v = static_cast<std::size_t>(order[k]);
    for (std::int64_t c = children.offset[v]; c < children.offset[v + 1]; ++c)
      subtree[v] += subtree[static_cast<std::size_t>(children.index[c])];
  }
  double total = 0;
  for (const double c : cost) total += c;

  // Split the largest piece into its root (to the top) and its daughters' subtrees, until the
  // largest is at most an eighth of a rank's share (dealt largest first, the loads then lie
  // within an eighth of a share of each other) and there are pieces for every rank; a piece of
  // one vessel cannot be split. On a small network the top grows as large as the pieces: of
  // the cuts on the way, the one whose deal has the smallest largest load is kept (each cut's
  // deal is tried while there are at most 4096 pieces; beyond, the top is a sliver).
  const double share = total / ranks;
  auto larger = [&](std::int32_t a, std::int32_t b) {
    const double ca = subtree[static_cast<std::size_t>(a)], cb = subtree[static_cast<std::size_t>(b)];
    return ca < cb || (ca == cb && a > b);  // the heap's top: largest, then lowest index
  };
  auto cut_after = [&](std::size_t splits, bool search, std::size_t& best_splits) {
    std::priority_queue<std::int32_t, std::vector<std::int32_t>, decltype(larger)> heap(larger, roots);
    Cut cut;
    double best = INFINITY;
    for (std::size_t done = 0;; ++done) {
      if (search && heap.size() <= 4096) {
        Cut now{{}, cut.top, cut.top_cost};
        auto copy = heap;
        for (; !copy.empty(); copy.pop()) now.pieces.push_back(copy.top());
        const double largest = deal(now, subtree, ranks).second;
        if (largest < best * (1 - 1e-12)) {
          best = largest;
          best_splits = done;
        }
      }
      const auto v = static_cast<std::size_t>(heap.top());
      const bool leaf = children.offset[v] == children.offset[v + 1];
      if (done == splits || leaf || (subtree[v] <= share / 8 && heap.size() >= static_cast<std::size_t>(ranks))) {
        if (search && heap.size() > 4096) best_splits = done;  // past the search: the rule's cut
        break;
      }
      heap.pop();
      cut.top.push_back(static_cast<std::int32_t>(v));
      cut.top_cost += cost[v];
      for (std::int64_t c = children.offset[v]; c < children.offset[v + 1]; ++c) heap.push(children.index[c]);
    }
    for (; !heap.empty(); heap.pop()) cut.pieces.push_back(heap.top());
    return cut;
  };
  std::size_t best_splits = 0;
  cut_after(SIZE_MAX, true, best_splits);
  std::size_t unused = 0;
  const Cut cut = cut_after(best_splits, false, unused);
  const std::vector<std::int32_t> rank = deal(cut, subtree, ranks).first;

  Partition p;
  p.method = Partition::Method::subtrees;
  p.ranks = ranks;
  p.rank_of_vessel.assign(n, -1);
  for (std::size_t k = 0; k < cut.pieces.size(); ++k) p.rank_of_vessel[static_cast<std::size_t>(cut.pieces[k])] = rank[k];
  p.top_rank = rank[cut.pieces.size()];
  p.top_vessels = cut.top.size();
  for (const std::int32_t v : cut.top) p.rank_of_vessel[static_cast<std::size_t>(v)] = p.top_rank;
  // Every other vessel with its piece's root: parents come first in order.
  for (const std::int32_t v : order)
    for (std::int64_t c = children.offset[v]; c < children.offset[v + 1]; ++c) {
      auto& daughter = p.rank_of_vessel[static_cast<std::size_t>(children.index[c])];
      if (daughter < 0) daughter = p.rank_of_vessel[static_cast<std::size_t>(v)];
    }
  return p;
}

}  // namespace hemotree
