// A tree's nodal system cut into shares and a top (distributed/tree_share.hpp), every rank
// played here in one process: the potentials are the whole system's bit for bit, for any
// number of ranks, whatever the order of the labels; a second solve with the same
// factorisation too; a cut that is not whole subtrees, and a graph that is not a forest, are
// refused; a forest with no path to ground is found singular.
#include <algorithm>
#include <bit>
#include <cstdint>
#include <numeric>
#include <random>

#include <gtest/gtest.h>

#include "grown_trees.hpp"

#include "core/setting_error.hpp"
#include "distributed/network_cut.hpp"
#include "distributed/tree_share.hpp"
#include "network_flow/nodal_system.hpp"
#include "partition/partition.hpp"
#include "physics/viscosity_table.hpp"
#include "pulse/lumped_vessels.hpp"
#include "steady/vessel_laws.hpp"

using namespace hemotree;

namespace {

using test_networks::grown_tree;

// Conductances spread over decades, as a tree's are; a shunt at every leaf (outlets) and a
// small one elsewhere (compliances); currents anywhere.
struct Numbers {
  std::vector<double> conductance, shunt, b;
};
Numbers numbers_for(std::size_t nodes, std::size_t edges, std::span<const std::int32_t> a, std::span<const std::int32_t> b,
                    unsigned seed) {
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> unit(0, 1);
  Numbers n;
  std::vector<int> degree(nodes, 0);
  for (std::size_t e = 0; e < edges; ++e) ++degree[static_cast<std::size_t>(a[e])], ++degree[static_cast<std::size_t>(b[e])];
  for (std::size_t e = 0; e < edges; ++e) n.conductance.push_back(std::pow(10.0, -12 + 4 * unit(random)));
  for (std::size_t i = 0; i < nodes; ++i) {
    n.shunt.push_back(degree[i] == 1 ? std::pow(10.0, -11 + 2 * unit(random)) : 1e-16 * unit(random));
    n.b.push_back(unit(random) - 0.5);
  }
  return n;
}

// Every rank's share and the top, played in turn: the potentials of the whole forest, and
// (where `again` is given) of a second right-hand side with the same factorisation.
std::vector<double> played(const TreeCut& cut, const Numbers& n, const std::vector<double>* again = nullptr,
                           std::vector<double>* again_x = nullptr, std::int64_t* singular = nullptr) {
  const std::size_t nodes = cut.owner.size();
  auto edge_conductance = [&](std::int32_t node) {
    const std::int32_t e = cut.parent_edge[static_cast<std::size_t>(node)];
    return e >= 0 ? n.conductance[static_cast<std::size_t>(e)] : 0.0;
  };
  std::vector<TreeShare> shares;
  std::vector<std::vector<std::int32_t>> share_nodes;
  std::vector<std::vector<double>> y(static_cast<std::size_t>(cut.ranks));
  std::vector<double> messages;
  for (int r = 0; r < cut.ranks; ++r) {
    shares.emplace_back(cut, r);
    share_nodes.push_back(cut.share_nodes(r));
    std::vector<double> g, s;
    for (const std::int32_t node : share_nodes.back()) {
      g.push_back(edge_conductance(node));
      s.push_back(n.shunt[static_cast<std::size_t>(node)]);
      y[static_cast<std::size_t>(r)].push_back(n.b[static_cast<std::size_t>(node)]);
    }
    const std::vector<double> m = shares.back().factorize_forward(g, s, y[static_cast<std::size_t>(r)]);
    messages.insert(messages.end(), m.begin(), m.end());
  }
  TreeTop top(cut);
  const std::vector<std::int32_t> top_nodes = cut.top_nodes();
  std::vector<double> g, s, b;
  for (const std::int32_t node : top_nodes) {
    g.push_back(edge_conductance(node));
    s.push_back(n.shunt[static_cast<std::size_t>(node)]);
    b.push_back(n.b[static_cast<std::size_t>(node)]);
  }
  std::vector<double> top_x(top_nodes.size()), answer(top.root_count());
  const std::int64_t found = top.factorize_solve(g, s, b, messages, top_x, answer);
  if (singular) *singular = found;
  if (found >= 0) return {};
  std::vector<double> x(nodes);
  auto finish = [&](std::vector<double>& out, std::vector<std::vector<double>>& forward, const std::vector<double>& top_out,
                    const std::vector<double>& top_answer) {
    for (std::size_t k = 0; k < top_nodes.size(); ++k) out[static_cast<std::size_t>(top_nodes[k])] = top_out[k];
    std::size_t slot = 0;
    for (int r = 0; r < cut.ranks; ++r) {
      const std::size_t count = shares[static_cast<std::size_t>(r)].root_count();
      shares[static_cast<std::size_t>(r)].backward(std::span<const double>(top_answer).subspan(slot, count),
                                                   forward[static_cast<std::size_t>(r)]);
      slot += count;
      for (std::size_t j = 0; j < share_nodes[static_cast<std::size_t>(r)].size(); ++j)
        out[static_cast<std::size_t>(share_nodes[static_cast<std::size_t>(r)][j])] = forward[static_cast<std::size_t>(r)][j];
    }
  };
  finish(x, y, top_x, answer);
  if (again) {
    std::vector<std::vector<double>> y2(static_cast<std::size_t>(cut.ranks));
    std::vector<double> messages2;
    for (int r = 0; r < cut.ranks; ++r) {
      for (const std::int32_t node : share_nodes[static_cast<std::size_t>(r)])
        y2[static_cast<std::size_t>(r)].push_back((*again)[static_cast<std::size_t>(node)]);
      const std::vector<double> m = shares[static_cast<std::size_t>(r)].forward(y2[static_cast<std::size_t>(r)]);
      messages2.insert(messages2.end(), m.begin(), m.end());
    }
    std::vector<double> b2;
    for (const std::int32_t node : top_nodes) b2.push_back((*again)[static_cast<std::size_t>(node)]);
    top.solve(b2, messages2, top_x, answer);
    again_x->assign(nodes, 0.0);
    finish(*again_x, y2, top_x, answer);
  }
  return x;
}

std::vector<double> whole(std::size_t nodes, const std::vector<std::int32_t>& a, const std::vector<std::int32_t>& b,
                          const Numbers& n, int threads = 1, const std::vector<double>* again = nullptr,
                          std::vector<double>* again_x = nullptr) {
  NodalSystem system(nodes, a, b);
  system.set_threads(threads);
  EXPECT_EQ(system.factorize(n.conductance, n.shunt), -1);
  std::vector<double> x(nodes);
  system.solve(n.b, x);
  if (again) {
    again_x->assign(nodes, 0.0);
    system.solve(*again, *again_x);
  }
  return x;
}

std::size_t bitwise_differences(const std::vector<double>& x, const std::vector<double>& y) {
  std::size_t d = 0;
  for (std::size_t i = 0; i < x.size(); ++i) d += std::bit_cast<std::uint64_t>(x[i]) != std::bit_cast<std::uint64_t>(y[i]);
  return d + (x.size() != y.size() ? 1 : 0);
}

}  // namespace

TEST(TreeShares, SweptShareByShareGiveTheWholeSystemsBitsForAnyRanks) {
  const Network net = grown_tree();
  ASSERT_GT(net.vessel_count(), 1000u);
  const Numbers n = numbers_for(net.node_count(), net.vessel_count(), net.from, net.to, 1);
  std::vector<double> again(net.node_count());
  std::iota(again.begin(), again.end(), -3.0);
  std::vector<double> whole_again;
  const std::vector<double> x = whole(net.node_count(), net.from, net.to, n, 1, &again, &whole_again);
  for (const int ranks : {1, 2, 3, 4, 7, 16}) {
    const Partition partition = partition_network(net, std::vector<double>(net.vessel_count(), 1.0), ranks);
    const TreeCut cut = tree_cut(net, partition);
    std::size_t roots = 0;
    for (const auto& r : cut.roots) roots += r.size();
    if (ranks > 1) {
      EXPECT_GE(roots, static_cast<std::size_t>(ranks) - 1) << ranks;
    }
    std::vector<double> played_again;
    EXPECT_EQ(bitwise_differences(played(cut, n, &again, &played_again), x), 0u) << ranks << " ranks";
    EXPECT_EQ(bitwise_differences(played_again, whole_again), 0u) << ranks << " ranks, second solve";
  }
}

// Labels that do not hang every node from a lower one: the forest's order is its peeled
// leaves (NodalSystem's and the cut's alike), and the shares follow it.
TEST(TreeShares, PeeledOrderAlsoGivesTheWholeSystemsBits) {
  const Network net = grown_tree();
  const std::size_t nodes = net.node_count();
  const auto [a, b] = test_networks::shuffled_edges(net, 7);
  const Numbers n = numbers_for(nodes, a.size(), a, b, 2);
  const std::vector<double> x = whole(nodes, a, b, n);
  const Partition partition = partition_network(net, std::vector<double>(net.vessel_count(), 1.0), 5);
  std::vector<std::int32_t> owner(partition.rank_of_vessel.begin(), partition.rank_of_vessel.end());
  for (const std::int32_t v : partition.top) owner[static_cast<std::size_t>(v)] = TreeCut::top;
  const TreeCut cut(nodes, a, b, owner, 5, partition.top_rank);
  std::vector<std::int32_t> identity(nodes);
  std::iota(identity.begin(), identity.end(), 0);
  ASSERT_NE(cut.order, identity);  // the peeled order is in use
  EXPECT_EQ(bitwise_differences(played(cut, n), x), 0u);
}

TEST(TreeShares, RefusesACutThatIsNotWholeSubtreesAndAGraphWithALoop) {
  // A chain 0 - 1 - 2 - 3: node 2 on rank 1 hanging from node 1 on rank 0.
  const std::vector<std::int32_t> a{0, 1, 2}, b{1, 2, 3};
  EXPECT_THROW(TreeCut(4, a, b, std::vector<std::int32_t>{0, 1, 1}, 2, 0), std::invalid_argument);
  // The top below a share: node 2 on the top hanging from node 1 on rank 0.
  EXPECT_THROW(TreeCut(4, a, b, std::vector<std::int32_t>{0, TreeCut::top, 0}, 2, 0), std::invalid_argument);
  // Whole subtrees: edges 0 and 1 on the top, edge 2 on rank 1.
  EXPECT_NO_THROW(TreeCut(4, a, b, std::vector<std::int32_t>{TreeCut::top, TreeCut::top, 1}, 2, 0));
  // A triangle.
  const std::vector<std::int32_t> ta{0, 1, 2}, tb{1, 2, 0};
  EXPECT_THROW(TreeCut(3, ta, tb, std::vector<std::int32_t>{0, 0, 0}, 1, 0), std::invalid_argument);
  // A rank out of range.
  EXPECT_THROW(TreeCut(4, a, b, std::vector<std::int32_t>{TreeCut::top, 2, 2}, 2, 0), std::invalid_argument);
}

// A singular forest is named as the whole system names it: its component's lowest node.
TEST(TreeShares, AForestWithNoPathToGroundIsNamedAsTheWholeNamesIt) {
  const Network net = grown_tree();
  Numbers n = numbers_for(net.node_count(), net.vessel_count(), net.from, net.to, 3);
  std::fill(n.shunt.begin(), n.shunt.end(), 0.0);
  const Partition partition = partition_network(net, std::vector<double>(net.vessel_count(), 1.0), 3);
  std::int64_t singular = -1;
  played(tree_cut(net, partition), n, nullptr, nullptr, &singular);
  NodalSystem system(net.node_count(), net.from, net.to);
  EXPECT_EQ(singular, system.factorize(n.conductance, n.shunt));
  // Peeled order: the forest's root (node 2 of edges 0-2, 1-2, 2-3) is not its lowest node,
  // and node 0 lies on rank 0's share.
  const std::vector<std::int32_t> a{0, 1, 2}, b{2, 2, 3};
  const TreeCut cut(4, a, b, std::vector<std::int32_t>{0, TreeCut::top, TreeCut::top}, 2, 1);
  const Numbers chain{{1.0, 2.0, 3.0}, {0.0, 0.0, 0.0, 0.0}, {1.0, 0.0, 0.0, 0.0}};
  NodalSystem whole_chain(4, a, b);
  played(cut, chain, nullptr, nullptr, &singular);
  EXPECT_EQ(singular, whole_chain.factorize(chain.conductance, chain.shunt));
  EXPECT_EQ(singular, 0);
}

// A rank may hold no share (here ranks 0 and 1: the top's rank holds the one subtree) and
// the forest several trees.
TEST(TreeShares, EmptySharesAndSeveralTreesGiveTheWholeSystemsBits) {
  // Two chains, 0-1-2-3 and 4-5-6: edge 0 (0-1) on the top, 1 and 2 on rank 2, 3 and 4 on rank 1.
  const std::vector<std::int32_t> a{0, 1, 2, 4, 5}, b{1, 2, 3, 5, 6};
  const Numbers n{{1e-9, 2e-9, 3e-9, 4e-9, 5e-9}, {0, 0, 0, 1e-10, 0, 0, 2e-10}, {1e-6, -2e-6, 3e-6, 0, 0.5e-6, 0, 1e-6}};
  const std::vector<double> x = whole(7, a, b, n);
  const TreeCut cut(7, a, b, std::vector<std::int32_t>{TreeCut::top, 2, 2, 1, 1}, 4, 2);
  EXPECT_TRUE(cut.roots[0].empty());
  EXPECT_TRUE(cut.roots[3].empty());
  EXPECT_EQ(bitwise_differences(played(cut, n), x), 0u);
}

TEST(TreeShares, ANetworkCutOnlyWhereItsTopIsOneRanks) {
  const Network net = grown_tree();
  Partition spread = partition_network(net, std::vector<double>(net.vessel_count(), 1.0), 4);
  spread.top_spread = true;
  spread.top_rank = -1;
  EXPECT_THROW(tree_cut(net, spread), SettingError);
}

namespace {

// A grown tree as a pulsatile run's 0D vessels take it: RCR outlets (capacitor nodes), a
// constant inflow, every seventh vessel in three sections (inner nodes).
struct ZeroDTree {
  Network net = test_networks::fed_tree(BoundaryType::rcr, Waveform::constant_value(1e-9 / 60));
  Blood blood = net.blood.value_or(Blood{});
  std::vector<TubeLaw> laws = vessel_laws(net, blood, 0.0, 0.1);
  ViscosityTable viscosity{blood};
  std::vector<std::uint8_t> sections = [this] {
    std::vector<std::uint8_t> s(net.vessel_count(), 1);
    for (std::size_t v = 3; v < s.size(); v += 7) s[v] = 3;
    return s;
  }();
};

}  // namespace

// The 0D vessels' system of a pulsatile run (pulse/lumped_vessels), in its own numbering (the
// subtree order, each RCR outlet's capacitor node after the network's nodes, the inner nodes
// of vessels in sections after them), its edges owned as the partition owns their vessels: a
// cut of whole subtrees whose shares, swept in turn, give its nodal system's bits: what a
// pulsatile run over ranks will solve a step with (docs/scaling.md, "the plan").
TEST(TreeShares, TheZeroDVesselsSystemInItsOwnNumberingCutsIntoShares) {
  const ZeroDTree t;
  const Network& net = t.net;
  const Blood& blood = t.blood;
  const std::vector<TubeLaw>& laws = t.laws;
  const ViscosityTable& viscosity = t.viscosity;
  const std::vector<std::uint8_t>& sections = t.sections;
  const LumpedVessels lumped(net, laws, viscosity, blood, std::vector<bool>(net.vessel_count(), true), {}, {}, sections);
  const std::size_t nodes = lumped.node_count();
  const std::vector<std::int32_t> a(lumped.edge_a().begin(), lumped.edge_a().end()), b(lumped.edge_b().begin(), lumped.edge_b().end());
  ASSERT_GT(nodes, net.node_count() + net.outlets.size());  // capacitors and inner nodes
  // Each vessel's edges: its sections, and an outlet's R1 edge.
  std::vector<int> edges_of(net.vessel_count(), 0);
  for (std::size_t e = 0; e < a.size(); ++e) ++edges_of[static_cast<std::size_t>(lumped.edge_vessel(e))];
  std::vector<int> expected(sections.begin(), sections.end());
  for (const Outlet& o : net.outlets) ++expected[static_cast<std::size_t>(o.vessel)];
  EXPECT_EQ(edges_of, expected);
  const Numbers n = numbers_for(nodes, a.size(), a, b, 4);
  const std::vector<double> x = whole(nodes, a, b, n);
  for (const int ranks : {2, 3, 5}) {
    const Partition partition = partition_network(net, std::vector<double>(net.vessel_count(), 1.0), ranks);
    std::vector<std::int32_t> owner(a.size());
    std::vector<std::uint8_t> top(net.vessel_count(), 0);
    for (const std::int32_t v : partition.top) top[static_cast<std::size_t>(v)] = 1;
    for (std::size_t e = 0; e < a.size(); ++e) {
      const auto v = static_cast<std::size_t>(lumped.edge_vessel(e));
      owner[e] = top[v] ? TreeCut::top : partition.rank_of_vessel[v];
    }
    const TreeCut cut(nodes, a, b, owner, ranks, partition.top_rank);  // refuses a cut that is not whole subtrees
    EXPECT_EQ(bitwise_differences(played(cut, n), x), 0u) << ranks << " ranks";
  }
}
