// A tree's harmonic system (complex two-ports, not symmetric) cut into shares and a top
// (distributed/harmonic_tree_share.hpp), every rank played here in one process: the
// potentials are the whole system's bit for bit, for any number of ranks, whatever the order
// of the labels; a rank may hold nothing; a forest with no admittance to ground is refused.
#include <algorithm>
#include <bit>
#include <cstdint>
#include <numeric>
#include <random>

#include <gtest/gtest.h>

#include "grown_trees.hpp"

#include "distributed/harmonic_tree_share.hpp"
#include "distributed/network_cut.hpp"
#include "network_flow/harmonic_system.hpp"
#include "partition/partition.hpp"

using namespace hemotree;

namespace {

using test_networks::grown_tree;

// Two-ports as a line with a mean flow gives them (series admittances over decades, a
// shunt at each end, the off-diagonal pair unequal); a shunt at every leaf (outlets' 1/Z)
// and currents anywhere.
struct Numbers {
  std::vector<TwoPort> edge;
  std::vector<Complex> shunt, current;
};
Numbers numbers_for(std::size_t nodes, std::span<const std::int32_t> a, std::span<const std::int32_t> b, unsigned seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> unit(0, 1);
  Numbers n;
  std::vector<int> degree(nodes, 0);
  for (std::size_t e = 0; e < a.size(); ++e) ++degree[static_cast<std::size_t>(a[e])], ++degree[static_cast<std::size_t>(b[e])];
  for (std::size_t e = 0; e < a.size(); ++e) {
    const Complex g(std::pow(10.0, -12 + 4 * unit(random)), 1e-13 * unit(random)), c(0, 1e-14 * unit(random));
    const double flow = 0.2 * (unit(random) - 0.5);
    n.edge.push_back({g + c, -g * (1.0 + flow), -g * (1.0 - flow), g + c * (1 + flow)});
  }
  for (std::size_t i = 0; i < nodes; ++i) {
    n.shunt.push_back(degree[i] == 1 ? Complex(std::pow(10.0, -11 + 2 * unit(random)), 1e-12 * unit(random))
                                     : Complex(0, 1e-16 * unit(random)));
    n.current.emplace_back(unit(random) - 0.5, unit(random) - 0.5);
  }
  return n;
}

// Every rank's share and the top, played in turn.
std::vector<Complex> played(const TreeCut& cut, std::span<const std::int32_t> a, const Numbers& n) {
  auto edge_to_parent = [&](std::int32_t node) {
    const std::int32_t e = cut.parent_edge[static_cast<std::size_t>(node)];
    if (e < 0) return EdgeToParent{};
    return EdgeToParent::of(n.edge[static_cast<std::size_t>(e)], a[static_cast<std::size_t>(e)] == node);
  };
  struct Part {
    std::vector<std::int32_t> nodes;
    std::vector<Complex> shunt, current;
    std::vector<EdgeToParent> edge;
  };
  auto part_of = [&](std::vector<std::int32_t> nodes) {
    Part p{std::move(nodes), {}, {}, {}};
    for (const std::int32_t node : p.nodes) {
      p.shunt.push_back(n.shunt[static_cast<std::size_t>(node)]);
      p.current.push_back(n.current[static_cast<std::size_t>(node)]);
      p.edge.push_back(edge_to_parent(node));
    }
    return p;
  };
  std::vector<HarmonicTreeShare> shares;
  std::vector<Part> parts;
  std::vector<Complex> messages;
  for (int r = 0; r < cut.ranks; ++r) {
    shares.emplace_back(cut, r);
    parts.push_back(part_of(cut.share_nodes(r)));
    const std::vector<Complex> m = shares.back().eliminate(parts.back().shunt, parts.back().edge, parts.back().current);
    messages.insert(messages.end(), m.begin(), m.end());
  }
  HarmonicTreeTop top(cut);
  const Part own = part_of(cut.top_nodes());
  std::vector<Complex> top_x(own.nodes.size()), answer(top.root_count());
  top.solve(own.shunt, own.current, own.edge, messages, top_x, answer);
  std::vector<Complex> x(cut.owner.size());
  for (std::size_t k = 0; k < own.nodes.size(); ++k) x[static_cast<std::size_t>(own.nodes[k])] = top_x[k];
  std::size_t slot = 0;
  for (std::size_t r = 0; r < shares.size(); ++r) {
    const std::size_t count = shares[r].root_count();
    shares[r].substitute(std::span<const Complex>(answer).subspan(slot, count), parts[r].current);
    slot += count;
    for (std::size_t j = 0; j < parts[r].nodes.size(); ++j) x[static_cast<std::size_t>(parts[r].nodes[j])] = parts[r].current[j];
  }
  return x;
}

std::vector<Complex> whole(std::size_t nodes, const std::vector<std::int32_t>& a, const std::vector<std::int32_t>& b,
                           const Numbers& n) {
  return HarmonicSystem(nodes, a, b).solve(n.edge, n.shunt, n.current);
}

std::size_t bitwise_differences(const std::vector<Complex>& x, const std::vector<Complex>& y) {
  std::size_t d = x.size() != y.size() ? 1 : 0;
  for (std::size_t i = 0; i < std::min(x.size(), y.size()); ++i)
    d += std::bit_cast<std::uint64_t>(x[i].real()) != std::bit_cast<std::uint64_t>(y[i].real()) ||
         std::bit_cast<std::uint64_t>(x[i].imag()) != std::bit_cast<std::uint64_t>(y[i].imag());
  return d;
}

}  // namespace

TEST(HarmonicTreeShares, SweptShareByShareGiveTheWholeSystemsBitsForAnyRanks) {
  const Network net = grown_tree();
  ASSERT_GT(net.vessel_count(), 1000u);
  const std::vector<std::int32_t> a(net.from.begin(), net.from.end()), b(net.to.begin(), net.to.end());
  const Numbers n = numbers_for(net.node_count(), a, b, 1);
  const std::vector<Complex> x = whole(net.node_count(), a, b, n);
  for (const int ranks : {1, 2, 3, 4, 7, 16}) {
    const Partition partition = partition_network(net, std::vector<double>(net.vessel_count(), 1.0), ranks);
    EXPECT_EQ(bitwise_differences(played(tree_cut(net, partition), a, n), x), 0u) << ranks << " ranks";
  }
  // Not a test that cannot fail: the same solve with one edge's coupling moved by 1e-13.
  Numbers moved = n;
  moved.edge[net.vessel_count() / 2].ab *= 1 + 1e-13;
  EXPECT_GT(bitwise_differences(whole(net.node_count(), a, b, moved), x), 0u);
}

// Labels that do not hang every node from a lower one (the peeled leaves' order) and edges
// that run either way between parent and child.
TEST(HarmonicTreeShares, PeeledOrderAndEitherOrientationGiveTheWholeSystemsBits) {
  const Network net = grown_tree();
  const std::size_t nodes = net.node_count();
  const auto [a, b] = test_networks::shuffled_edges(net, 7, 3);
  const Numbers n = numbers_for(nodes, a, b, 2);
  const std::vector<Complex> x = whole(nodes, a, b, n);
  for (const int ranks : {2, 5}) {
    const Partition partition = partition_network(net, std::vector<double>(net.vessel_count(), 1.0), ranks);
    std::vector<std::int32_t> owner(partition.rank_of_vessel.begin(), partition.rank_of_vessel.end());
    for (const std::int32_t v : partition.top) owner[static_cast<std::size_t>(v)] = TreeCut::top;
    const TreeCut cut(nodes, a, b, owner, ranks, partition.top_rank);
    EXPECT_EQ(bitwise_differences(played(cut, a, n), x), 0u) << ranks << " ranks";
  }
}

// A rank may hold no share, the forest several trees, and a node no edge (a held pressure's).
TEST(HarmonicTreeShares, EmptySharesSeveralTreesAndLoneNodesGiveTheWholeSystemsBits) {
  // Chains 0-1-2-3 and 4-5-6, node 7 alone: edge 0 on the top, 1 and 2 on rank 2, 3 and 4 on rank 1.
  const std::vector<std::int32_t> a{0, 1, 2, 4, 5}, b{1, 2, 3, 5, 6};
  Numbers n = numbers_for(8, a, b, 3);
  n.shunt[7] = 1.0;
  const std::vector<Complex> x = whole(8, a, b, n);
  const TreeCut cut(8, a, b, std::vector<std::int32_t>{TreeCut::top, 2, 2, 1, 1}, 4, 2);
  EXPECT_TRUE(cut.roots[0].empty());
  EXPECT_EQ(bitwise_differences(played(cut, a, n), x), 0u);
}

TEST(HarmonicTreeShares, AForestWithNoAdmittanceToGroundIsRefused) {
  // A chain whose two edges are pure series admittances and no shunt anywhere: the top's
  // last pivot is zero.
  const std::vector<std::int32_t> a{0, 1, 2}, b{1, 2, 3};
  Numbers n;
  for (int e = 0; e < 3; ++e) n.edge.push_back(TwoPort::series(Complex(1.0, 0.5)));
  n.shunt.assign(4, 0.0);
  n.current.assign(4, 1.0);
  EXPECT_THROW(whole(4, a, b, n), SingularHarmonicSystem);
  const TreeCut cut(4, a, b, std::vector<std::int32_t>{TreeCut::top, 0, 0}, 2, 1);
  try {
    played(cut, a, n);
    ADD_FAILURE() << "no refusal";
  } catch (const SingularHarmonicSystem& e) {
    EXPECT_LT(e.node, 4u);
    EXPECT_NE(std::string(e.what()).find("no admittance to ground"), std::string::npos);
  }
}
