#include "pulse/lumped_cut.hpp"

#include <stdexcept>
#include <string>

namespace hemotree {

LumpedCut lumped_cut(const Network& net, const LumpedOrder& whole, std::span<const std::int32_t> vessel_rank,
                     int ranks, int top_rank, int rank, std::span<const std::uint8_t> sections) {
  if (ranks < 1 || top_rank < 0 || top_rank >= ranks || rank < 0 || rank >= ranks)
    throw std::invalid_argument("lumped_cut: rank " + std::to_string(rank) + " and the top on " +
                                std::to_string(top_rank) + " of " + std::to_string(ranks));
  // Each node's place in the order; a vessel's upper end is the earlier, and the vessel above
  // a node the one whose lower end it is.
  std::vector<std::int32_t> place(net.node_count(), -1), above(net.node_count(), -1);
  for (std::size_t k = 0; k < whole.nodes.size(); ++k) place[static_cast<std::size_t>(whole.nodes[k])] = static_cast<std::int32_t>(k);
  auto ends = [&](std::int32_t v, std::int32_t& upper, std::int32_t& lower) {
    const std::int32_t a = net.from[static_cast<std::size_t>(v)], b = net.to[static_cast<std::size_t>(v)];
    const bool a_first = place[static_cast<std::size_t>(a)] < place[static_cast<std::size_t>(b)];
    upper = a_first ? a : b;
    lower = a_first ? b : a;
  };
  for (const std::int32_t v : whole.vessels) {
    std::int32_t upper, lower;
    ends(v, upper, lower);
    if (above[static_cast<std::size_t>(lower)] >= 0)
      throw std::invalid_argument("lumped_cut: node " + std::to_string(net.node_id[static_cast<std::size_t>(lower)]) +
                                  " ends two 0D vessels from above (the 0D vessels are not a tree in their order)");
    above[static_cast<std::size_t>(lower)] = v;
  }
  auto rank_of = [&](std::int32_t v) { return vessel_rank[static_cast<std::size_t>(v)]; };
  // The root vessels: a share's vessels that hang from the top's rank's, or from a root.
  std::vector<std::vector<std::int32_t>> roots(static_cast<std::size_t>(ranks));
  std::vector<bool> keep(net.vessel_count(), false);
  LumpedCut cut;
  cut.rank = rank;
  cut.top_rank = top_rank;
  for (const std::int32_t v : whole.vessels) {
    // A vessel in sections numbers its inner nodes after every network node: the forest no
    // longer hangs each node from one before it, and a share's elimination would not run in
    // the whole's order (docs/scaling.md).
    if (!sections.empty() && sections[static_cast<std::size_t>(v)] > 1)
      throw std::invalid_argument("lumped_cut: vessel " + std::to_string(net.id[static_cast<std::size_t>(v)]) + " is in " +
                                  std::to_string(sections[static_cast<std::size_t>(v)]) +
                                  " pi sections; a run over ranks takes one section a 0D vessel");
    const std::int32_t r = rank_of(v);
    if (r < 0 || r >= ranks)
      throw std::invalid_argument("lumped_cut: vessel " + std::to_string(net.id[static_cast<std::size_t>(v)]) + " on rank " +
                                  std::to_string(r) + " of " + std::to_string(ranks));
    if (r == rank) keep[static_cast<std::size_t>(v)] = true;
    if (r == top_rank) continue;
    std::int32_t upper, lower;
    ends(v, upper, lower);
    const std::int32_t parent = above[static_cast<std::size_t>(upper)];
    if (parent >= 0 && rank_of(parent) == r) continue;
    if (parent >= 0 && rank_of(parent) != top_rank)
      throw std::invalid_argument("lumped_cut: vessel " + std::to_string(net.id[static_cast<std::size_t>(v)]) + " on rank " +
                                  std::to_string(r) + " hangs from vessel " +
                                  std::to_string(net.id[static_cast<std::size_t>(parent)]) + " on rank " +
                                  std::to_string(rank_of(parent)) + ", not the top's (" + std::to_string(top_rank) + ")");
    roots[static_cast<std::size_t>(r)].push_back(v);
    if (rank == top_rank) {
      keep[static_cast<std::size_t>(v)] = true;
      cut.ghost_nodes.push_back(lower);
    } else if (r == rank) {
      cut.root_vessels.push_back(v);
      cut.ghost_nodes.push_back(upper);
    }
  }
  cut.order = restrict_order(whole, net, keep);
  for (const auto& share : roots) cut.roots.push_back(static_cast<int>(share.size()));
  if (rank == top_rank)
    for (const auto& share : roots) cut.root_vessels.insert(cut.root_vessels.end(), share.begin(), share.end());
  return cut;
}

}  // namespace hemotree
