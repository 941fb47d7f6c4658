// The 1D vessels' cut over ranks (pulse/one_d_cut.hpp): which rows a rank steps, which
// junctions it solves, and which traces it sends and receives; what one rank sends another
// receives, end for end, so that both hold the same numbers at a junction; and which coupled
// 1D ends meet another rank's 0D node.
#include <gtest/gtest.h>

#include <vector>

#include "network_builders.hpp"
#include "pulse/one_d_cut.hpp"

namespace hemotree {
namespace {

using test_networks::bifurcation;

// Two bifurcations in a row: 0 -> 1, 1 -> 2, 1 -> 3, then 2 -> 4, 2 -> 5; inlet at 0.
Network two_bifurcations() {
  Network net = bifurcation();
  net.add_node(4);
  net.add_node(5);
  net.add_vessel(3, 2, 4, 0.01, 1e-4, 1e-5, 2e5, 2);
  net.add_vessel(4, 2, 5, 0.01, 1e-4, 1e-5, 2e5, 2);
  net.inlet = Inlet{0, Waveform{}};
  for (const std::int32_t v : {2, 3, 4}) net.outlets.push_back(test_networks::resistance_outlet(v, 1e9, 0));
  return net;
}

TEST(OneDCut, EachRankStepsItsRowsAndSharesTheJunctionsAcrossTheCut) {
  const Network net = two_bifurcations();
  const int e = 2;  // elements per vessel
  // Vessels 0, 1 and 4 of degree 1 (elements 0-5), 2 and 3 of degree 3 (elements 6-9).
  const std::vector<std::int32_t> first = {0, 2, 6, 8, 4};
  const std::vector<bool> zero_d(5, false);
  const NetworkBoundaries ends = build_boundaries(net, first, e, zero_d);
  ASSERT_EQ(ends.junction_offset.size(), 3u);  // nodes 1 and 2
  std::vector<std::int32_t> element_vessel(10);
  for (std::int32_t v = 0; v < 5; ++v)
    for (int k = 0; k < e; ++k) element_vessel[static_cast<std::size_t>(first[static_cast<std::size_t>(v)] + k)] = v;
  const std::vector<ElementRun> blocks = {{1, 0, 6}, {3, 6, 4}};
  const std::vector<std::int32_t> rank = {0, 0, 1, 0, 1};  // vessels 2 and 4 on rank 1

  const OneDCut zero = one_d_cut(ends, blocks, element_vessel, rank, 0);
  const OneDCut one = one_d_cut(ends, blocks, element_vessel, rank, 1);
  // Rank 0 steps vessels 0, 1 (elements 0-3) and 3 (8, 9); rank 1 vessels 4 (4, 5) and 2 (6, 7).
  ASSERT_EQ(zero.runs.size(), 2u);
  EXPECT_EQ(zero.runs[0].degree, 1);
  EXPECT_EQ(zero.runs[0].first, 0);
  EXPECT_EQ(zero.runs[0].count, 4);
  EXPECT_EQ(zero.runs[1].degree, 3);
  EXPECT_EQ(zero.runs[1].first, 8);
  EXPECT_EQ(zero.runs[1].count, 2);
  ASSERT_EQ(one.runs.size(), 2u);
  EXPECT_EQ(one.runs[0].first, 4);
  EXPECT_EQ(one.runs[0].count, 2);
  EXPECT_EQ(one.runs[1].first, 6);
  EXPECT_EQ(one.runs[1].count, 2);
  // Both junctions hold ends of both ranks: each rank solves both.
  EXPECT_EQ(zero.junctions, (std::vector<std::int64_t>{0, 1}));
  EXPECT_EQ(one.junctions, (std::vector<std::int64_t>{0, 1}));
  // One neighbour each; what one sends, in order, is what the other receives.
  ASSERT_EQ(zero.neighbours.size(), 1u);
  ASSERT_EQ(one.neighbours.size(), 1u);
  EXPECT_EQ(zero.neighbours[0].rank, 1);
  EXPECT_EQ(one.neighbours[0].rank, 0);
  auto same = [](const std::vector<VesselEnd>& a, const std::vector<VesselEnd>& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t k = 0; k < a.size(); ++k)
      if (a[k].vessel != b[k].vessel || a[k].element != b[k].element || a[k].distal != b[k].distal) return false;
    return true;
  };
  EXPECT_TRUE(same(zero.neighbours[0].send, one.neighbours[0].receive));
  EXPECT_TRUE(same(one.neighbours[0].send, zero.neighbours[0].receive));
  // Rank 0 sends vessels 0 and 1's ends at node 1, then vessel 1's and 3's at node 2.
  ASSERT_EQ(zero.neighbours[0].send.size(), 4u);
  // Rank 1 sends vessel 2's proximal end at node 1 and vessel 4's at node 2.
  ASSERT_EQ(one.neighbours[0].send.size(), 2u);
  EXPECT_EQ(one.neighbours[0].send[0].vessel, 2);
  EXPECT_FALSE(one.neighbours[0].send[0].distal);
  EXPECT_EQ(one.neighbours[0].send[0].element, 6);
}

TEST(OneDCut, ARankAloneSolvesItsJunctionsAndSendsNothing) {
  const Network net = two_bifurcations();
  const std::vector<std::int32_t> first = {0, 1, 2, 3, 4};
  const NetworkBoundaries ends = build_boundaries(net, first, 1, std::vector<bool>(5, false));
  const std::vector<std::int32_t> element_vessel = {0, 1, 2, 3, 4};
  const std::vector<ElementRun> blocks = {{2, 0, 5}};
  // Vessels 0, 1 and 2 on rank 0 hold node 1 whole; node 2 joins 1 (rank 0) with 3 and 4 (rank 1).
  const std::vector<std::int32_t> rank = {0, 0, 0, 1, 1};
  const OneDCut zero = one_d_cut(ends, blocks, element_vessel, rank, 0);
  const OneDCut one = one_d_cut(ends, blocks, element_vessel, rank, 1);
  EXPECT_EQ(zero.junctions, (std::vector<std::int64_t>{0, 1}));
  EXPECT_EQ(one.junctions, (std::vector<std::int64_t>{1}));
  ASSERT_EQ(zero.neighbours.size(), 1u);
  EXPECT_EQ(zero.neighbours[0].send.size(), 1u);     // vessel 1's distal end
  EXPECT_EQ(zero.neighbours[0].receive.size(), 2u);  // vessels 3 and 4's proximal ends
  const OneDCut alone = one_d_cut(ends, blocks, element_vessel, std::vector<std::int32_t>(5, 0), 0);
  ASSERT_EQ(alone.runs.size(), 1u);
  EXPECT_EQ(alone.runs[0].count, 5);
  EXPECT_TRUE(alone.neighbours.empty());
  EXPECT_EQ(alone.junctions.size(), 2u);
}

TEST(CouplingCut, EndsAtAnotherRanksNodesGoThereInTheCoupledEndsOrder) {
  // Vessels 1 and 3 are 0D: vessel 0's distal end and vessel 2's proximal end meet 1 at node
  // 1; vessel 4's proximal end meets 3 at node 2 (vessel 1's distal end is 0D).
  const Network net = two_bifurcations();
  const std::vector<bool> zero_d = {false, true, false, true, false};
  const std::vector<std::int32_t> first = {0, -1, 1, -1, 2};
  const NetworkBoundaries ends = build_boundaries(net, first, 1, zero_d);
  ASSERT_EQ(ends.coupled.size(), 3u);
  const std::vector<std::int32_t> rank = {0, 1, 0, 1, 0};  // the 0D vessels on rank 1
  std::vector<std::int32_t> node_rank(net.node_count(), -1);
  node_rank[1] = node_rank[2] = node_rank[4] = 1;
  const CouplingCut zero = coupling_cut(ends, rank, node_rank, 0), one = coupling_cut(ends, rank, node_rank, 1);
  ASSERT_EQ(zero.neighbours.size(), 1u);
  ASSERT_EQ(one.neighbours.size(), 1u);
  EXPECT_EQ(zero.neighbours[0].rank, 1);
  EXPECT_EQ(zero.neighbours[0].ends, (std::vector<std::int32_t>{0, 1, 2}));  // all three: rank 0's ends
  EXPECT_TRUE(zero.neighbours[0].nodes.empty());
  EXPECT_EQ(one.neighbours[0].nodes, zero.neighbours[0].ends);
  EXPECT_TRUE(one.neighbours[0].ends.empty());
  // The ends and their nodes on one rank: nothing crosses.
  const std::vector<std::int32_t> together = {1, 1, 1, 1, 1};
  EXPECT_TRUE(coupling_cut(ends, together, node_rank, 1).neighbours.empty());
}

}  // namespace
}  // namespace hemotree
