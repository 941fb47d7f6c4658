// pulse/lumped_order: the 0D vessels kept with every sweep task's subtree contiguous, and the
// elimination in that order the same, bit for bit, as in the network's.
#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "network_flow/nodal_system.hpp"
#include "pulse/lumped_order.hpp"

namespace hemotree {
namespace {

// A tree of `nodes` nodes numbered breadth first from its root (vgen's order): node k > 0
// hangs from a random earlier node among the last `width`, its vessel is k - 1, and a random
// half of the vessels run from child to parent.
Network breadth_first_tree(std::int32_t nodes, std::int32_t width, unsigned seed) {
  std::mt19937 random(seed);
  Network net;
  for (std::int32_t k = 0; k < nodes; ++k) net.add_node(1000 + k);
  for (std::int32_t k = 1; k < nodes; ++k) {
    const std::int32_t lowest = std::max(0, k - width);
    std::int32_t parent = std::uniform_int_distribution<std::int32_t>(lowest, k - 1)(random);
    const bool reversed = random() % 2 == 0;
    net.add_vessel(k - 1, reversed ? k : parent, reversed ? parent : k, 1e-3, 1e-5, 1e-6, 1e6, 1);
  }
  return net;
}

struct Numbered {
  std::vector<std::int32_t> a, b, node_place, vessel_place;  // place: new index of a network node / vessel
};

Numbered number(const Network& net, const LumpedOrder& order) {
  Numbered n;
  n.node_place.assign(net.node_count(), -1);
  n.vessel_place.assign(net.vessel_count(), -1);
  for (std::size_t k = 0; k < order.nodes.size(); ++k) n.node_place[static_cast<std::size_t>(order.nodes[k])] = static_cast<std::int32_t>(k);
  for (std::size_t e = 0; e < order.vessels.size(); ++e) {
    const auto v = static_cast<std::size_t>(order.vessels[e]);
    n.vessel_place[v] = static_cast<std::int32_t>(e);
    n.a.push_back(n.node_place[static_cast<std::size_t>(net.from[v])]);
    n.b.push_back(n.node_place[static_cast<std::size_t>(net.to[v])]);
  }
  return n;
}

TEST(LumpedOrder, EveryTaskIsContiguousAndTheEliminationTheSameBits) {
  const std::int32_t nodes = 150000;  // above NodalSystem's 2^16: the sweeps take tasks
  const Network net = breadth_first_tree(nodes, 3000, 7);
  const std::vector<bool> zero_d(net.vessel_count(), true);
  const LumpedOrder given = network_lumped_order(net, zero_d), order = subtree_lumped_order(net, zero_d);
  ASSERT_EQ(order.nodes.size(), given.nodes.size());
  ASSERT_EQ(order.vessels.size(), given.vessels.size());
  EXPECT_NE(order.nodes, given.nodes);
  const Numbered g = number(net, given), s = number(net, order);
  for (const std::int32_t p : s.node_place) ASSERT_GE(p, 0);  // a permutation of both
  for (const std::int32_t p : s.vessel_place) ASSERT_GE(p, 0);

  // Every node hangs from one lower node (the elimination's own order), and each task's
  // nodes, the largest subtrees within the limit, fill one range.
  std::vector<std::int32_t> parent(static_cast<std::size_t>(nodes), -1), size(static_cast<std::size_t>(nodes), 1);
  for (std::size_t e = 0; e < s.a.size(); ++e) {
    const std::int32_t high = std::max(s.a[e], s.b[e]);
    ASSERT_EQ(parent[static_cast<std::size_t>(high)], -1);
    parent[static_cast<std::size_t>(high)] = std::min(s.a[e], s.b[e]);
  }
  for (std::size_t k = static_cast<std::size_t>(nodes); k-- > 1;) size[static_cast<std::size_t>(parent[k])] += size[k];
  const auto limit = static_cast<std::int32_t>(NodalSystem::task_size_limit(static_cast<std::size_t>(nodes)));
  ASSERT_GT(limit, 0);
  int tasks = 0;
  for (std::size_t k = 0; k < static_cast<std::size_t>(nodes); ++k) {
    const bool root = size[k] <= limit && (parent[k] < 0 || size[static_cast<std::size_t>(parent[k])] > limit);
    if (!root) continue;
    ++tasks;
    for (std::size_t j = k + 1; j < k + static_cast<std::size_t>(size[k]); ++j) {  // its subtree is [k, k + size)
      std::size_t up = j;
      while (up > k) up = static_cast<std::size_t>(parent[up]);
      ASSERT_EQ(up, k) << "node " << j << " is not in the task rooted at " << k;
    }
  }
  EXPECT_GT(tasks, 32);

  // The same system in both orders: the same pivots and potentials, bit for bit, on one
  // thread and on two (the tasks).
  std::mt19937 random(3);
  std::uniform_real_distribution<double> u(0.5, 2.0);
  std::vector<double> conductance(net.vessel_count()), shunt(static_cast<std::size_t>(nodes)), rhs(shunt.size());
  for (double& x : conductance) x = u(random);
  for (double& x : shunt) x = random() % 4 == 0 ? u(random) : 0.0;
  for (double& x : rhs) x = u(random) - 1.25;
  auto solve = [&](const Numbered& n, int threads) {
    std::vector<double> c(conductance.size()), sh(shunt.size()), y(rhs.size());
    for (std::size_t v = 0; v < conductance.size(); ++v) c[static_cast<std::size_t>(n.vessel_place[v])] = conductance[v];
    for (std::size_t k = 0; k < shunt.size(); ++k) {
      sh[static_cast<std::size_t>(n.node_place[k])] = shunt[k];
      y[static_cast<std::size_t>(n.node_place[k])] = rhs[k];
    }
    NodalSystem system(shunt.size(), n.a, n.b);
    system.set_threads(threads);
    EXPECT_EQ(system.method(), NodalSystem::Method::tree_elimination);
    EXPECT_LT(system.factorize(c, sh), 0);
    system.solve(y, y);
    std::vector<double> x(y.size());
    for (std::size_t k = 0; k < x.size(); ++k) x[k] = y[static_cast<std::size_t>(n.node_place[k])];
    return x;
  };
  const std::vector<double> reference = solve(g, 1);
  for (int threads : {1, 2})
    for (const Numbered* n : {&g, &s}) {
      const std::vector<double> x = solve(*n, threads);
      for (std::size_t k = 0; k < x.size(); ++k) ASSERT_EQ(x[k], reference[k]) << "node " << k << ", " << threads << " threads";
    }
}

TEST(LumpedOrder, SmallTreesAndGraphsWithLoopsKeepTheNetworksOrder) {
  const Network small = breadth_first_tree(1000, 50, 1);
  const std::vector<bool> all(small.vessel_count(), true);
  EXPECT_EQ(subtree_lumped_order(small, all).nodes, network_lumped_order(small, all).nodes);

  Network loop = breadth_first_tree(100000, 3000, 2);
  loop.add_vessel(99999, 5, 99990, 1e-3, 1e-5, 1e-6, 1e6, 1);  // closes a loop
  const std::vector<bool> every(loop.vessel_count(), true);
  const LumpedOrder given = network_lumped_order(loop, every), order = subtree_lumped_order(loop, every);
  EXPECT_EQ(order.nodes, given.nodes);
  EXPECT_EQ(order.vessels, given.vessels);

  // Only the 0D vessels count: without the loop's vessel, a forest again.
  std::vector<bool> tree(loop.vessel_count(), true);
  tree.back() = false;
  EXPECT_NE(subtree_lumped_order(loop, tree).nodes, network_lumped_order(loop, tree).nodes);
}

}  // namespace
}  // namespace hemotree
