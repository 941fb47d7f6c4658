// Any graph split by METIS (partition/partition.hpp): the nodes, each weighted by the cost of
// the vessels leaving it, cut into k parts of balanced weight along few vessels; a vessel goes
// with its `from` node.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>
#include <vector>

#include <metis.h>

#include "core/errors.hpp"
#include "partition/partition_methods.hpp"

namespace hemotree {

Partition partition_with_metis(const Network& net, std::span<const double> cost, int ranks) {
  const std::size_t nodes = net.node_count();
  // Undirected adjacency without repeats (two vessels between the same nodes are one edge).
  std::vector<std::pair<idx_t, idx_t>> edges;
  edges.reserve(2 * net.vessel_count());
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    edges.emplace_back(net.from[v], net.to[v]);
    edges.emplace_back(net.to[v], net.from[v]);
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  std::vector<idx_t> offset(nodes + 1, 0), adjacent(edges.size());
  for (std::size_t e = 0; e < edges.size(); ++e) {
    ++offset[static_cast<std::size_t>(edges[e].first) + 1];
    adjacent[e] = edges[e].second;
  }
  for (std::size_t k = 0; k < nodes; ++k) offset[k + 1] += offset[k];
  // Integer weights, each vessel's whole cost on its `from` node, the node it goes with (a
  // node only entered weighs nothing): in units that give the least cost 100 (two digits of
  // the ratios), or fewer where the total would pass 2^30 (METIS's 32-bit sums); each vessel
  // at least 1.
  const double total = std::accumulate(cost.begin(), cost.end(), 0.0);
  const double least = *std::min_element(cost.begin(), cost.end());
  const double scale = std::min(100 / least, std::ldexp(1.0, 30) / total);
  std::vector<idx_t> weight(nodes, 0);
  for (std::size_t v = 0; v < net.vessel_count(); ++v)
    weight[static_cast<std::size_t>(net.from[v])] += static_cast<idx_t>(std::max(1.0, std::round(cost[v] * scale)));
  idx_t vertices = static_cast<idx_t>(nodes), constraints = 1, parts = ranks, edge_cut = 0;
  std::vector<idx_t> part(nodes, 0);
  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_SEED] = 1;  // the same partition every time
  options[METIS_OPTION_NUMBERING] = 0;
  const int status = METIS_PartGraphKway(&vertices, &constraints, offset.data(), adjacent.data(), weight.data(),
                                         nullptr, nullptr, &parts, nullptr, nullptr, options, &edge_cut, part.data());
  if (status != METIS_OK)
    throw InputError("METIS could not split the network into " + std::to_string(ranks) + " parts (status " +
                     std::to_string(status) + ")");
  Partition p;
  p.method = Partition::Method::metis;
  p.ranks = ranks;
  p.rank_of_vessel.resize(net.vessel_count());
  for (std::size_t v = 0; v < net.vessel_count(); ++v)
    p.rank_of_vessel[v] = static_cast<std::int32_t>(part[static_cast<std::size_t>(net.from[v])]);
  return p;
}

}  // namespace hemotree
