// The vessels split over ranks (partition/partition.hpp): whole subtrees on trees within the
// bound that dealing pieces of at most an eighth of a share largest first guarantees
// (the largest load at most the mean plus the largest piece: 1 + 1/8), by cost not by count,
// METIS on looped networks, the cut nodes counted again here, the same answer every time, and
// the refusals.
#include <algorithm>
#include <set>

#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "core/setting_error.hpp"
#include "formats/topology.hpp"
#include "generator/growth_rules.hpp"
#include "generator/tree_growth.hpp"
#include "partition/partition.hpp"

using namespace hemotree;

namespace {

Network grown_tree() {
  GrowthParameters p;
  p.root_diameter = 150e-6;
  p.min_diameter = 7e-6;
  return grow_tree(default_rules(), p);
}

// An n x n grid of nodes joined right and down: loops everywhere.
Network grid(int n) {
  Network net;
  for (int k = 0; k < n * n; ++k) net.add_node(k);
  std::int64_t id = 0;
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) {
      if (c + 1 < n) net.add_vessel(id++, r * n + c, r * n + c + 1, 1e-3, 20e-6, 2e-6, 1e5, 0);
      if (r + 1 < n) net.add_vessel(id++, r * n + c, (r + 1) * n + c, 1e-3, 20e-6, 2e-6, 1e5, 0);
    }
  return net;
}

// Nodes touched by vessels of two ranks, counted by sets.
std::size_t cut_nodes_by_sets(const Network& net, const std::vector<std::int32_t>& rank) {
  std::vector<std::set<std::int32_t>> at(net.node_count());
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    at[static_cast<std::size_t>(net.from[v])].insert(rank[v]);
    at[static_cast<std::size_t>(net.to[v])].insert(rank[v]);
  }
  return static_cast<std::size_t>(std::count_if(at.begin(), at.end(), [](const auto& s) { return s.size() > 1; }));
}

void expect_consistent(const Network& net, const std::vector<double>& cost, const Partition& p) {
  ASSERT_EQ(p.rank_of_vessel.size(), net.vessel_count());
  std::vector<double> load(static_cast<std::size_t>(p.ranks), 0);
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    ASSERT_GE(p.rank_of_vessel[v], 0);
    ASSERT_LT(p.rank_of_vessel[v], p.ranks);
    load[static_cast<std::size_t>(p.rank_of_vessel[v])] += cost[v];
  }
  for (int r = 0; r < p.ranks; ++r) EXPECT_NEAR(load[static_cast<std::size_t>(r)], p.cost[static_cast<std::size_t>(r)], 1e-9);
  EXPECT_EQ(p.cut_nodes, cut_nodes_by_sets(net, p.rank_of_vessel));
}

}  // namespace

TEST(Partition, ATreeIntoWholeSubtreesWithinTheBoundOfItsPieces) {
  const Network net = grown_tree();
  ASSERT_GT(net.vessel_count(), 2000u);
  const std::vector<double> cost(net.vessel_count(), 1.0);
  const Children children = children_of(net);
  for (int ranks = 1; ranks <= 8; ++ranks) {
    const Partition p = partition_network(net, cost, ranks);
    expect_consistent(net, cost, p);
    EXPECT_EQ(p.method, ranks == 1 ? Partition::Method::single : Partition::Method::subtrees);
    EXPECT_LE(p.imbalance(), 1.125) << ranks;
    // Whole subtrees: a vessel whose daughters lie on another rank is one of the top's.
    std::size_t parents_of_a_cut = 0;
    for (std::size_t v = 0; v < net.vessel_count(); ++v)
      for (std::int64_t c = children.offset[v]; c < children.offset[v + 1]; ++c)
        if (p.rank_of_vessel[static_cast<std::size_t>(children.index[c])] != p.rank_of_vessel[v]) {
          ++parents_of_a_cut;
          EXPECT_EQ(p.rank_of_vessel[v], p.top_rank);
          break;
        }
    EXPECT_LE(parents_of_a_cut, p.top_vessels) << ranks;
    // The same partition every time.
    EXPECT_EQ(partition_network(net, cost, ranks).rank_of_vessel, p.rank_of_vessel);
  }
}

TEST(Partition, BalancesCostNotCount) {
  const Network net = grown_tree();
  // The vessels of the root's first daughter's subtree cost 20 times the others'.
  const Children children = children_of(net);
  const std::size_t root = check_rooted_tree(net);
  std::vector<double> cost(net.vessel_count(), 1.0);
  std::vector<std::int32_t> stack{children.index[static_cast<std::size_t>(children.offset[root])]};
  while (!stack.empty()) {
    const auto v = static_cast<std::size_t>(stack.back());
    stack.pop_back();
    cost[v] = 20;
    for (std::int64_t c = children.offset[v]; c < children.offset[v + 1]; ++c) stack.push_back(children.index[c]);
  }
  const Partition p = partition_network(net, cost, 4);
  expect_consistent(net, cost, p);
  EXPECT_LE(p.imbalance(), 1.125);
  const auto [fewest, most] = std::minmax_element(p.vessels.begin(), p.vessels.end());
  EXPECT_GT(static_cast<double>(*most) / static_cast<double>(*fewest), 3.0);  // counts far apart, costs not
}

TEST(Partition, ALoopedNetworkByMetis) {
  const Network net = grid(40);
  const std::vector<double> cost(net.vessel_count(), 1.0);
  for (int ranks : {2, 3, 4}) {
    const Partition p = partition_network(net, cost, ranks);
    EXPECT_EQ(p.method, Partition::Method::metis);
    expect_consistent(net, cost, p);
    EXPECT_LE(p.imbalance(), 1.1) << ranks;
    // A grid of 40 x 40 cut into k parts along a few lines of nodes, not scattered.
    EXPECT_LT(p.cut_nodes, static_cast<std::size_t>(60 * ranks)) << ranks;
    EXPECT_EQ(partition_network(net, cost, ranks).rank_of_vessel, p.rank_of_vessel);
  }
}

TEST(Partition, RefusesMoreRanksThanVesselsAndAnEmptyRank) {
  const Network net = grid(2);  // 4 vessels in a loop
  const std::vector<double> cost(net.vessel_count(), 1.0);
  EXPECT_THROW(partition_network(net, cost, 5), SettingError);
  EXPECT_THROW(partition_network(net, cost, 0), SettingError);
  try {
    partition_network(net, cost, 5);
  } catch (const SettingError& e) {
    EXPECT_NE(e.in_words({}).find("ranks 5: more ranks than the 4 vessels"), std::string::npos) << e.in_words({});
  }
}
