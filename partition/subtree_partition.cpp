// Whole subtrees to each rank (partition/partition.hpp): pieces split from the top, largest
// first, then dealt largest first to the least loaded rank.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <queue>
#include <unordered_map>
#include <utility>
#include <vector>

#include "formats/topology.hpp"
#include "partition/partition_methods.hpp"

namespace hemotree {

namespace {

// A cut of the forest: the pieces (subtrees, by their root vessels) and the top, the vessels
// split off above them in the order they were split (each before its daughters).
struct Cut {
  std::vector<std::int32_t> pieces, top;
  double top_cost = 0;
};

// A cut dealt to the ranks: each piece's rank, and the top's: on one rank as one more piece
// (its small system one rank's to solve), or, where that deals worse (the top outgrows a
// rank's share when there are many ranks for the vessels), each top vessel with its first
// daughter. largest: the largest load; infinite where a rank would be left empty.
struct Deal {
  std::vector<std::int32_t> piece_rank;
  bool top_spread = false;
  std::int32_t top_rank = 0;
  double largest = INFINITY;
};

class Dealer {
 public:
  Dealer(const Children& children, const std::vector<double>& subtree, std::span<const double> cost, int ranks)
      : children_(children), subtree_(subtree), cost_(cost), ranks_(ranks),
        share_(std::accumulate(cost.begin(), cost.end(), 0.0) / ranks) {}

  // The top on one rank while that deal keeps within the bound of pieces of an eighth of a
  // share (the largest load at most 9/8 of the mean), else spread where that deals better.
  Deal deal(const Cut& cut) const {
    Deal whole = lpt(cut, true);
    if (cut.top.empty() || whole.largest <= share_ * 9 / 8) return whole;
    Deal spread = lpt(cut, false);
    if (spread.piece_rank.empty()) return whole;  // fewer pieces than ranks
    spread.top_spread = true;
    spread_top(cut, spread);
    return spread.largest < whole.largest ? spread : whole;
  }

  // Every top vessel's rank in a spread deal, deepest first: its first daughter's.
  std::unordered_map<std::int32_t, std::int32_t> spread_ranks(const Cut& cut, const Deal& deal) const {
    std::unordered_map<std::int32_t, std::int32_t> rank;
    for (std::size_t k = 0; k < cut.pieces.size(); ++k) rank[cut.pieces[k]] = deal.piece_rank[k];
    for (auto v = cut.top.rbegin(); v != cut.top.rend(); ++v)
      rank[*v] = rank.at(children_.index[static_cast<std::size_t>(children_.offset[static_cast<std::size_t>(*v)])]);
    return rank;
  }

 private:
  // Largest first (the lowest index of equals), each to the least loaded rank (the lowest of
  // equals): the pieces, and the top as one more where with_top.
  Deal lpt(const Cut& cut, bool with_top) const {
    Deal d;
    const bool top_piece = with_top && !cut.top.empty();
    if (cut.pieces.size() + (top_piece ? 1 : 0) < static_cast<std::size_t>(ranks_)) return d;  // a rank left empty: no ranks
    std::vector<std::pair<double, std::size_t>> items;  // (cost, piece; the top is pieces.size())
    items.reserve(cut.pieces.size() + 1);
    for (std::size_t k = 0; k < cut.pieces.size(); ++k)
      items.emplace_back(subtree_[static_cast<std::size_t>(cut.pieces[k])], k);
    if (top_piece) items.emplace_back(cut.top_cost, cut.pieces.size());
    std::stable_sort(items.begin(), items.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    using Load = std::pair<double, std::int32_t>;  // (load, rank): the least, then the lowest rank
    std::priority_queue<Load, std::vector<Load>, std::greater<>> loads;
    for (std::int32_t r = 0; r < ranks_; ++r) loads.emplace(0.0, r);
    d.piece_rank.assign(cut.pieces.size() + 1, 0);
    for (const auto& [c, k] : items) {
      auto [load, r] = loads.top();
      loads.pop();
      d.piece_rank[k] = r;
      loads.emplace(load + c, r);
    }
    d.top_rank = d.piece_rank.back();
    d.piece_rank.pop_back();
    double largest = 0;
    for (; !loads.empty(); loads.pop()) largest = std::max(largest, loads.top().first);
    d.largest = largest;  // a spread top's share is added by spread_top
    return d;
  }

  void spread_top(const Cut& cut, Deal& d) const {
    std::vector<double> load(static_cast<std::size_t>(ranks_), 0.0);
    for (std::size_t k = 0; k < cut.pieces.size(); ++k)
      load[static_cast<std::size_t>(d.piece_rank[k])] += subtree_[static_cast<std::size_t>(cut.pieces[k])];
    const auto rank = spread_ranks(cut, d);
    for (const std::int32_t v : cut.top) load[static_cast<std::size_t>(rank.at(v))] += cost_[static_cast<std::size_t>(v)];
    d.largest = *std::max_element(load.begin(), load.end());
  }

  const Children& children_;
  const std::vector<double>& subtree_;
  std::span<const double> cost_;
  int ranks_;
  double share_;
};

}  // namespace

bool is_forest(const Network& net) {
  std::vector<std::uint8_t> entered(net.node_count(), 0);
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    auto& e = entered[static_cast<std::size_t>(net.to[v])];
    if (e) return false;
    e = 1;
  }
  // With in-degrees at most one, a vessel not reached from a root lies on a directed cycle.
  return breadth_first_order(children_of(net), inlet_vessels(net)).size() == net.vessel_count();
}

Partition partition_subtrees(const Network& net, std::span<const double> cost, int ranks) {
  const std::size_t n = net.vessel_count();
  const Children children = children_of(net);
  const std::vector<std::int32_t> roots = inlet_vessels(net);
  const std::vector<std::int32_t> order = breadth_first_order(children, roots);
  auto has_daughters = [&](std::int32_t v) {
    return children.offset[static_cast<std::size_t>(v)] != children.offset[static_cast<std::size_t>(v) + 1];
  };
  // The cost of each vessel's subtree, daughters before parents.
  std::vector<double> subtree(cost.begin(), cost.end());
  for (std::size_t k = n; k-- > 0;) {
    const auto v = static_cast<std::size_t>(order[k]);
    for (std::int64_t c = children.offset[v]; c < children.offset[v + 1]; ++c)
      subtree[v] += subtree[static_cast<std::size_t>(children.index[c])];
  }
  const double share = std::accumulate(cost.begin(), cost.end(), 0.0) / ranks;
  const Dealer dealer(children, subtree, cost, ranks);

  // Split the largest piece that has daughters into its root (to the top) and its daughters'
  // subtrees, until that largest is at most an eighth of a rank's share (dealt largest first,
  // the loads then lie within an eighth of a share of each other) and there are pieces for
  // every rank; a piece of one vessel stays whole. Of the cuts on the way (each dealt while
  // there are at most 4096 pieces) and the last, the one whose deal has the smallest largest
  // load is kept, the earliest of equals (fewer cut nodes): on a small network the top grows
  // as large as the pieces.
  auto larger = [&](std::int32_t a, std::int32_t b) {
    const double ca = subtree[static_cast<std::size_t>(a)], cb = subtree[static_cast<std::size_t>(b)];
    return ca < cb || (ca == cb && a > b);  // the heap's top: largest, then lowest index
  };
  auto cut_after = [&](std::size_t splits, bool search, std::size_t& best_splits) {
    std::priority_queue<std::int32_t, std::vector<std::int32_t>, decltype(larger)> splittable(larger);
    Cut cut;  // its pieces: the vessels without daughters set apart so far
    for (const std::int32_t r : roots) {
      if (has_daughters(r)) splittable.push(r);
      else cut.pieces.push_back(r);
    }
    double best = INFINITY;
    auto consider = [&](std::size_t done) {
      Cut now{cut.pieces, cut.top, cut.top_cost};
      for (auto copy = splittable; !copy.empty(); copy.pop()) now.pieces.push_back(copy.top());
      const double largest = dealer.deal(now).largest;
      if (largest < best * (1 - 1e-12)) {
        best = largest;
        best_splits = done;
      }
    };
    for (std::size_t done = 0;; ++done) {
      const std::size_t pieces = splittable.size() + cut.pieces.size();
      const bool last = splittable.empty() || done == splits ||
                        (subtree[static_cast<std::size_t>(splittable.top())] <= share / 8 &&
                         pieces >= static_cast<std::size_t>(ranks));
      if (search && (pieces <= 4096 || last)) consider(done);
      if (last) break;
      const std::int32_t v = splittable.top();
      splittable.pop();
      cut.top.push_back(v);
      cut.top_cost += cost[static_cast<std::size_t>(v)];
      for (std::int64_t c = children.offset[static_cast<std::size_t>(v)]; c < children.offset[static_cast<std::size_t>(v) + 1]; ++c) {
        const std::int32_t d = children.index[c];
        if (has_daughters(d)) splittable.push(d);
        else cut.pieces.push_back(d);
      }
    }
    for (; !splittable.empty(); splittable.pop()) cut.pieces.push_back(splittable.top());
    return cut;
  };
  std::size_t best_splits = 0, unused = 0;
  cut_after(SIZE_MAX, true, best_splits);
  const Cut cut = cut_after(best_splits, false, unused);
  const Deal deal = dealer.deal(cut);

  Partition p;
  p.method = Partition::Method::subtrees;
  p.ranks = ranks;
  if (!std::isfinite(deal.largest)) {  // every cut leaves a rank empty: the caller refuses it
    p.rank_of_vessel.assign(n, 0);
    return p;
  }
  p.rank_of_vessel.assign(n, -1);
  for (std::size_t k = 0; k < cut.pieces.size(); ++k) p.rank_of_vessel[static_cast<std::size_t>(cut.pieces[k])] = deal.piece_rank[k];
  p.top = cut.top;
  p.top_spread = deal.top_spread;
  p.top_rank = deal.top_spread ? -1 : deal.top_rank;
  if (deal.top_spread) {
    for (const auto& [v, r] : dealer.spread_ranks(cut, deal)) p.rank_of_vessel[static_cast<std::size_t>(v)] = r;
  } else {
    for (const std::int32_t v : cut.top) p.rank_of_vessel[static_cast<std::size_t>(v)] = deal.top_rank;
  }
  // Every other vessel with its piece's root: parents come first in order.
  for (const std::int32_t v : order)
    for (std::int64_t c = children.offset[static_cast<std::size_t>(v)]; c < children.offset[static_cast<std::size_t>(v) + 1]; ++c) {
      auto& daughter = p.rank_of_vessel[static_cast<std::size_t>(children.index[c])];
      if (daughter < 0) daughter = p.rank_of_vessel[static_cast<std::size_t>(v)];
    }
  return p;
}

}  // namespace hemotree
