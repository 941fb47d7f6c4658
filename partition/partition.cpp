#include "partition/partition.hpp"

#include "formats/topology.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <utility>

#include "core/errors.hpp"
#include "core/setting_error.hpp"
#include "partition/partition_methods.hpp"

namespace hemotree {

double Partition::imbalance() const {
  if (cost.empty()) return 1;
  const double total = std::accumulate(cost.begin(), cost.end(), 0.0);
  return total > 0 ? *std::max_element(cost.begin(), cost.end()) / (total / static_cast<double>(cost.size())) : 1;
}

const char* to_string(Partition::Method method) {
  switch (method) {
    case Partition::Method::single: return "one rank";
    case Partition::Method::subtrees: return "subtrees";
    case Partition::Method::metis: return "METIS";
  }
  return "?";
}

std::vector<std::int32_t> node_owners(const Network& net, const Partition& partition) {
  std::vector<std::int32_t> owner(net.node_count(), -1);
  for (std::size_t v = 0; v < net.vessel_count(); ++v) owner[static_cast<std::size_t>(net.from[v])] = partition.rank_of_vessel[v];
  for (std::size_t v = 0; v < net.vessel_count(); ++v)
    if (std::int32_t& o = owner[static_cast<std::size_t>(net.to[v])]; o < 0) o = partition.rank_of_vessel[v];
  for (std::int32_t& o : owner) o = std::max(o, 0);
  return owner;
}

std::size_t count_cut_nodes(const Network& net, std::span<const std::int32_t> rank_of_vessel) {
  std::vector<std::int32_t> seen(net.node_count(), -1);
  std::vector<std::uint8_t> cut(net.node_count(), 0);
  for (std::size_t v = 0; v < net.vessel_count(); ++v)
    for (const std::int32_t node : {net.from[v], net.to[v]}) {
      auto& s = seen[static_cast<std::size_t>(node)];
      if (s < 0) s = rank_of_vessel[v];
      else if (s != rank_of_vessel[v]) cut[static_cast<std::size_t>(node)] = 1;
    }
  return static_cast<std::size_t>(std::count(cut.begin(), cut.end(), std::uint8_t{1}));
}

namespace {

// Each rank's cost and vessels, and the cut nodes, from the ranks of the vessels; a rank left
// without a vessel refused.
void count_ranks(const Network& net, std::span<const double> cost, Partition& p) {
  const std::size_t n = net.vessel_count();
  p.cost.assign(static_cast<std::size_t>(p.ranks), 0.0);
  p.vessels.assign(static_cast<std::size_t>(p.ranks), 0);
  for (std::size_t v = 0; v < n; ++v) {
    p.cost[static_cast<std::size_t>(p.rank_of_vessel[v])] += cost[v];
    ++p.vessels[static_cast<std::size_t>(p.rank_of_vessel[v])];
  }
  for (int r = 0; r < p.ranks; ++r)
    if (p.vessels[static_cast<std::size_t>(r)] == 0)
      throw SettingError("ranks", placeholder("ranks") + ": a partition of " + std::to_string(n) + " vessels into " +
                                      std::to_string(p.ranks) + " ranks leaves rank " + std::to_string(r) +
                                      " without a vessel (" + to_string(p.method) + "): use fewer ranks");
  p.cut_nodes = count_cut_nodes(net, p.rank_of_vessel);
}

}  // namespace

Partition partition_network(const Network& net, std::span<const double> cost, int ranks) {
  const std::size_t n = net.vessel_count();
  if (cost.size() != n) throw std::invalid_argument("partition_network: one cost per vessel");
  if (ranks < 1)
    throw SettingError("ranks", placeholder("ranks") + " must be at least 1 (got " + std::to_string(ranks) + ")");
  if (n == 0) throw SettingError("ranks", placeholder("ranks") + ": the network has no vessels to split");
  if (static_cast<std::size_t>(ranks) > n)
    throw SettingError("ranks", placeholder("ranks") + " " + std::to_string(ranks) + ": more ranks than the " +
                                    std::to_string(n) + " vessels (at most one rank a vessel)");
  for (std::size_t v = 0; v < n; ++v)
    if (!(cost[v] > 0) || !std::isfinite(cost[v]))
      throw std::invalid_argument("partition_network: a vessel's cost must be positive");
  Partition p;
  if (ranks == 1) {
    p.rank_of_vessel.assign(n, 0);
  } else {
    p = is_forest(net) ? partition_subtrees(net, cost, ranks) : partition_with_metis(net, cost, ranks);
  }
  p.ranks = ranks;
  count_ranks(net, cost, p);
  return p;
}

void keep_on_top(const Network& net, std::span<const double> cost, std::span<const std::uint8_t> on_top, Partition& p) {
  if (on_top.size() != net.vessel_count()) throw std::invalid_argument("keep_on_top: a byte per vessel");
  if (p.method != Partition::Method::subtrees || p.top_spread) return;  // one rank; METIS and a spread top have none
  const Children children = children_of(net);
  std::vector<std::int32_t> parent(net.vessel_count(), -1);
  for (std::size_t v = 0; v < net.vessel_count(); ++v)
    for (std::int64_t c = children.offset[v]; c < children.offset[v + 1]; ++c)
      parent[static_cast<std::size_t>(children.index[c])] = static_cast<std::int32_t>(v);
  std::vector<std::uint8_t> top(net.vessel_count(), 0);
  for (const std::int32_t v : p.top) top[static_cast<std::size_t>(v)] = 1;
  // Up from each vessel asked for to the top: every vessel on the way joins it, parents
  // before their daughters.
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    if (!on_top[v] || top[v]) continue;
    std::vector<std::int32_t> path;
    for (auto u = static_cast<std::int32_t>(v); u >= 0 && !top[static_cast<std::size_t>(u)]; u = parent[static_cast<std::size_t>(u)])
      path.push_back(u);
    for (auto u = path.rbegin(); u != path.rend(); ++u) {
      top[static_cast<std::size_t>(*u)] = 1;
      p.top.push_back(*u);
      p.rank_of_vessel[static_cast<std::size_t>(*u)] = p.top_rank;
    }
  }
  count_ranks(net, cost, p);
}

void lead_with_the_top(Partition& p) {
  if (p.method != Partition::Method::subtrees || p.top_spread || p.top_rank <= 0) return;
  const std::int32_t top = p.top_rank;
  for (std::int32_t& r : p.rank_of_vessel) r = r == top ? 0 : r == 0 ? top : r;
  std::swap(p.cost[0], p.cost[static_cast<std::size_t>(top)]);
  std::swap(p.vessels[0], p.vessels[static_cast<std::size_t>(top)]);
  p.top_rank = 0;
}

std::string describe(const Partition& p) {
  std::ostringstream s;
  const auto [fewest, most] = std::minmax_element(p.vessels.begin(), p.vessels.end());
  s << p.ranks << (p.ranks == 1 ? " rank" : " ranks");
  if (p.ranks > 1) s << " by " << to_string(p.method);
  s << ": " << *fewest;
  if (*most != *fewest) s << " to " << *most;
  s << " vessels a rank, cost imbalance " << std::fixed;
  s.precision(3);
  s << p.imbalance() << " (the largest over the mean), " << p.cut_nodes << " cut nodes";
  if (p.method == Partition::Method::subtrees && p.top_spread)
    s << ", the top's " << p.top.size() << " vessels each with its first daughter";
  else if (p.method == Partition::Method::subtrees && !p.top.empty())
    s << ", the top's " << p.top.size() << " vessels on rank " << p.top_rank;
  return s.str();
}

}  // namespace hemotree
