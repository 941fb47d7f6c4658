// The nodal system (network_flow/nodal_system) against dense solves of the same matrix built
// here independently, and its two methods against each other.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <random>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "network_flow/nodal_system.hpp"

using namespace hemotree;
using Method = NodalSystem::Method;

namespace {

struct Graph {
  std::size_t nodes = 0;
  std::vector<std::int32_t> a, b;
};

// (sum_e g_e (u_a - u_b)(u_a - u_b)^T + diag(s)), entry by entry.
Eigen::MatrixXd dense_matrix(const Graph& graph, const std::vector<double>& g, const std::vector<double>& s) {
  const auto n = static_cast<Eigen::Index>(graph.nodes);
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(n, n);
  for (std::size_t e = 0; e < graph.a.size(); ++e) {
    const Eigen::Index i = graph.a[e], j = graph.b[e];
    m(i, i) += g[e];
    m(j, j) += g[e];
    m(i, j) -= g[e];
    m(j, i) -= g[e];
  }
  for (Eigen::Index i = 0; i < n; ++i) m(i, i) += s[static_cast<std::size_t>(i)];
  return m;
}

std::vector<double> dense_solve(const Graph& graph, const std::vector<double>& g, const std::vector<double>& s,
                                const std::vector<double>& rhs) {
  const Eigen::VectorXd x =
      dense_matrix(graph, g, s).partialPivLu().solve(Eigen::Map<const Eigen::VectorXd>(rhs.data(), rhs.size()));
  return {x.data(), x.data() + x.size()};
}

// The 2-norm condition number: a dense solve is good to about cond * 1e-16, so the tests
// that compare with one keep it below 1e4 (their tolerance, 1e-12, then holds with margin).
double condition(const Graph& graph, const std::vector<double>& g, const std::vector<double>& s) {
  const Eigen::VectorXd lambda = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(dense_matrix(graph, g, s)).eigenvalues();
  return lambda.maxCoeff() / lambda.minCoeff();
}

// max_i |x_i - y_i| / max_i |y_i|
double relative_difference(const std::vector<double>& x, const std::vector<double>& y) {
  double diff = 0, scale = 0;
  for (std::size_t i = 0; i < y.size(); ++i) {
    diff = std::max(diff, std::abs(x[i] - y[i]));
    scale = std::max(scale, std::abs(y[i]));
  }
  return diff / scale;
}

std::vector<double> solved(NodalSystem& system, const std::vector<double>& g, const std::vector<double>& s,
                           const std::vector<double>& rhs) {
  EXPECT_EQ(system.factorize(g, s), -1);
  std::vector<double> x(rhs.size());
  system.solve(rhs, x);
  return x;
}

std::vector<double> uniform(std::size_t count, double low, double high, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(low, high);
  std::vector<double> v(count);
  for (double& x : v) x = u(rng);
  return v;
}

// Conductances over four decades, as vessels' 1/R spread.
std::vector<double> log_uniform(std::size_t count, double low, double high, std::mt19937_64& rng) {
  std::vector<double> v = uniform(count, std::log(low), std::log(high), rng);
  for (double& x : v) x = std::exp(x);
  return v;
}

// A ring of five nodes with two chords (0-2, 1-3): loops, no parallel edge.
Graph ring_with_chords() {
  return {5, {0, 1, 2, 3, 4, 0, 1}, {1, 2, 3, 4, 0, 2, 3}};
}

// A random tree: node k > 0 hangs from a random earlier node, numbered so (as a grown network
// is: the system takes its own order then) or under shuffled labels (it peels leaves then).
Graph random_tree(std::size_t nodes, std::mt19937_64& rng, bool shuffled = true) {
  std::vector<std::int32_t> label(nodes);
  for (std::size_t k = 0; k < nodes; ++k) label[k] = static_cast<std::int32_t>(k);
  if (shuffled) std::shuffle(label.begin(), label.end(), rng);
  Graph t;
  t.nodes = nodes;
  for (std::size_t k = 1; k < nodes; ++k) {
    std::uniform_int_distribution<std::size_t> earlier(0, k - 1);
    t.a.push_back(label[earlier(rng)]);
    t.b.push_back(label[k]);
  }
  return t;
}

}  // namespace

TEST(NodalSystem, ALoopedGraphAgreesWithADenseSolve) {
  std::mt19937_64 rng(7);
  const Graph graph = ring_with_chords();
  const std::vector<double> g = log_uniform(graph.a.size(), 1e-1, 1e1, rng);
  const std::vector<double> s{0, 0.3, 0, 0, 2.5};
  const std::vector<double> rhs = uniform(graph.nodes, -1, 1, rng);
  ASSERT_LT(condition(graph, g, s), 1e4);
  NodalSystem system(graph.nodes, graph.a, graph.b);
  EXPECT_EQ(system.method(), Method::sparse_cholesky);
  EXPECT_EQ(system.node_count(), 5u);
  EXPECT_EQ(system.edge_count(), 7u);
  const std::vector<double> x = solved(system, g, s, rhs);
  EXPECT_LT(relative_difference(x, dense_solve(graph, g, s, rhs)), 1e-12);
  // And the residual of the matrix built here, against its scale (entries up to ~30).
  const Eigen::VectorXd residual = dense_matrix(graph, g, s) * Eigen::Map<const Eigen::VectorXd>(x.data(), 5) -
                                   Eigen::Map<const Eigen::VectorXd>(rhs.data(), 5);
  EXPECT_LT(residual.lpNorm<Eigen::Infinity>(), 1e-13);
}

TEST(NodalSystem, ADoubledEdgeAddsItsConductances) {
  NodalSystem doubled(2, {0, 1}, {1, 0});
  EXPECT_EQ(doubled.method(), Method::sparse_cholesky);
  const std::vector<double> x = solved(doubled, {1.0, 3.0}, {0.0, 1.0}, {1.0, 0.0});
  // 1 A into node 0, through 1/4 ohm to node 1, through 1 ohm to ground.
  EXPECT_NEAR(x[1], 1.0, 1e-15);
  EXPECT_NEAR(x[0], 1.25, 1e-15);
}

// A step of compliant vessels: conductances over two decades, C/dt at every node.
TEST(NodalSystem, ALargeRandomTreeSolvesTheSameByBothMethods) {
  std::mt19937_64 rng(2024);
  for (const bool shuffled : {false, true}) {
    const Graph tree = random_tree(2000, rng, shuffled);
    const std::vector<double> g = log_uniform(tree.a.size(), 1e-1, 1e1, rng);
    const std::vector<double> s = uniform(tree.nodes, 1e-2, 1e-1, rng);
    const std::vector<double> rhs = uniform(tree.nodes, -1, 1, rng);
    NodalSystem automatic(tree.nodes, tree.a, tree.b);
    NodalSystem cholesky(tree.nodes, tree.a, tree.b, Method::sparse_cholesky);
    EXPECT_EQ(automatic.method(), Method::tree_elimination);
    EXPECT_EQ(cholesky.method(), Method::sparse_cholesky);
    EXPECT_LT(relative_difference(solved(automatic, g, s, rhs), solved(cholesky, g, s, rhs)), 1e-12)
        << "shuffled " << shuffled;
  }
}

// Grounded at a tenth of its nodes, as a network at its outlets; numbered from its root and
// not.
TEST(NodalSystem, ATreeAgreesWithADenseSolve) {
  std::mt19937_64 rng(99);
  for (const bool shuffled : {false, true}) {
    const Graph tree = random_tree(200, rng, shuffled);
    const std::vector<double> g = log_uniform(tree.a.size(), 1e-1, 1e1, rng);
    std::vector<double> s(tree.nodes, 0.0);
    for (std::size_t i = 0; i < tree.nodes; i += 10) s[i] = 0.5;
    const std::vector<double> rhs = uniform(tree.nodes, -1, 1, rng);
    ASSERT_LT(condition(tree, g, s), 1e4);
    NodalSystem elimination(tree.nodes, tree.a, tree.b, Method::tree_elimination);
    NodalSystem cholesky(tree.nodes, tree.a, tree.b, Method::sparse_cholesky);
    const std::vector<double> exact = dense_solve(tree, g, s, rhs);
    EXPECT_LT(relative_difference(solved(elimination, g, s, rhs), exact), 1e-12) << "shuffled " << shuffled;
    EXPECT_LT(relative_difference(solved(cholesky, g, s, rhs), exact), 1e-12) << "shuffled " << shuffled;
  }
}

// A chain of 1000 nodes, conductances over twelve decades, grounded through 1 at its far end
// and fed 1 at node 0: node k sits at the sum of the resistances from it to ground. The
// elimination adds series conductances as g S / (g + S), never subtracting, so it gets every
// node's potential to a few ulps per node of the chain (measured: 4e-15), where the condition
// number allows a factorisation that subtracts far less: the sparse Cholesky, in its AMD
// order, is off by 7e-4 here.
TEST(NodalSystem, TheEliminationIsExactToRoundingAlongAnIllConditionedChain) {
  std::mt19937_64 rng(3);
  const std::size_t n = 1000;
  Graph chain{n, {}, {}};
  for (std::size_t k = 0; k + 1 < n; ++k) {
    chain.a.push_back(static_cast<std::int32_t>(k));
    chain.b.push_back(static_cast<std::int32_t>(k + 1));
  }
  const std::vector<double> g = log_uniform(n - 1, 1e-6, 1e6, rng);
  std::vector<double> s(n, 0.0), rhs(n, 0.0);
  s[n - 1] = 1.0;
  rhs[0] = 1.0;
  NodalSystem system(chain.nodes, chain.a, chain.b);
  ASSERT_EQ(system.method(), Method::tree_elimination);
  const std::vector<double> x = solved(system, g, s, rhs);
  long double beyond = 1;  // the resistance from node k to ground, summed from the far end
  for (std::size_t k = n; k-- > 0;) {
    EXPECT_NEAR(x[k], static_cast<double>(beyond), 1e-12 * static_cast<double>(beyond)) << "node " << k;
    if (k > 0) beyond += 1.0L / g[k - 1];
  }
}

// A chain 0 - 1 - 2 - 3 of unit conductances grounded at 3 through 1: a current I into node 0
// flows through all four resistances in series, so node k sits at (4 - k) I.
TEST(NodalSystem, AChainIsFourResistancesInSeries) {
  for (const Method method : {Method::tree_elimination, Method::sparse_cholesky}) {
    NodalSystem chain(4, {2, 1, 0}, {3, 2, 1}, method);
    const std::vector<double> x = solved(chain, {1, 1, 1}, {0, 0, 0, 1}, {2, 0, 0, 0});
    for (std::size_t k = 0; k < 4; ++k) EXPECT_NEAR(x[k], 2.0 * (4.0 - static_cast<double>(k)), 1e-14);
  }
}

TEST(NodalSystem, AForestOfTwoTreesEachWithAShunt) {
  std::mt19937_64 rng(5);
  // Nodes 0..3 a star around 2, nodes 4..6 a chain; interleaved labels would not matter.
  const Graph forest{7, {2, 2, 2, 4, 5}, {0, 1, 3, 5, 6}};
  const std::vector<double> g = uniform(forest.a.size(), 0.5, 2, rng);
  const std::vector<double> s{0, 0, 0, 0.7, 0, 0, 1.3};
  const std::vector<double> rhs = uniform(forest.nodes, -1, 1, rng);
  for (const Method method : {Method::automatic, Method::sparse_cholesky}) {
    NodalSystem system(forest.nodes, forest.a, forest.b, method);
    EXPECT_EQ(system.method(), method == Method::automatic ? Method::tree_elimination : method);
    EXPECT_LT(relative_difference(solved(system, g, s, rhs), dense_solve(forest, g, s, rhs)), 1e-12);
  }
}

// The second tree of the forest has no shunt: its lowest node (4) is named, by both methods;
// on the looped graph, the whole graph when no node has a shunt.
TEST(NodalSystem, AComponentWithoutAPathToGroundIsNamed) {
  const Graph forest{7, {2, 2, 2, 5, 4}, {0, 1, 3, 6, 5}};
  const std::vector<double> g(forest.a.size(), 1.0);
  const std::vector<double> s{0, 0.2, 0, 0, 0, 0, 0};
  for (const Method method : {Method::tree_elimination, Method::sparse_cholesky}) {
    NodalSystem system(forest.nodes, forest.a, forest.b, method);
    EXPECT_EQ(system.factorize(g, s), 4);
    std::vector<double> x(forest.nodes);
    EXPECT_THROW(system.solve(x, x), std::logic_error);  // nothing to solve with
  }
  const Graph ring = ring_with_chords();
  NodalSystem looped(ring.nodes, ring.a, ring.b);
  EXPECT_EQ(looped.factorize(std::vector<double>(ring.a.size(), 1.0), std::vector<double>(ring.nodes, 0.0)), 0);
  // An isolated node without a shunt is a component of its own.
  NodalSystem lonely(3, {0}, {1});
  EXPECT_EQ(lonely.factorize(std::vector<double>{1.0}, std::vector<double>{1.0, 0, 0}), 2);
}

// A shunt lost in rounding (1e-16 against conductances of 1): the sparse Cholesky's last pivot
// is rounding noise, and it reports the system singular rather than solve it; the tree
// elimination adds the series conductances without subtracting and solves it exactly: 1 into
// node 0 through two unit resistances and 1e16 to ground.
TEST(NodalSystem, AShuntLostInRoundingIsSingularOnlyToTheCholesky) {
  const std::vector<double> g{1.0, 1.0}, s{0, 0, 1e-16};
  NodalSystem cholesky(3, {0, 1}, {1, 2}, Method::sparse_cholesky);
  EXPECT_EQ(cholesky.factorize(g, s), 0);
  NodalSystem elimination(3, {0, 1}, {1, 2}, Method::tree_elimination);
  const std::vector<double> x = solved(elimination, g, s, {1, 0, 0});
  for (std::size_t k = 0; k < 3; ++k) EXPECT_NEAR(x[k], 1e16 + static_cast<double>(2 - k), 1e-15 * 1e16);
}

TEST(NodalSystem, RefusesMalformedGraphs) {
  EXPECT_THROW(NodalSystem(3, {0, 1}, {1, 1}), std::invalid_argument);   // a self-loop
  EXPECT_THROW(NodalSystem(3, {0, 1}, {1, 3}), std::invalid_argument);   // node 3 of 3
  EXPECT_THROW(NodalSystem(3, {0, -1}, {1, 2}), std::invalid_argument);  // negative
  EXPECT_THROW(NodalSystem(3, {0, 1}, {1}), std::invalid_argument);      // ends unpaired
  const Graph ring = ring_with_chords();
  EXPECT_THROW(NodalSystem(ring.nodes, ring.a, ring.b, Method::tree_elimination), std::invalid_argument);
  EXPECT_THROW(NodalSystem(2, {0, 1}, {1, 0}, Method::tree_elimination), std::invalid_argument);
  NodalSystem chain(3, {0, 1}, {1, 2});
  EXPECT_THROW(chain.factorize(std::vector<double>{1.0}, std::vector<double>{1, 1, 1}), std::invalid_argument);
  EXPECT_THROW(chain.factorize(std::vector<double>{1.0, 0.0}, std::vector<double>{1, 1, 1}), std::invalid_argument);
  EXPECT_THROW(chain.factorize(std::vector<double>{1.0, 1.0}, std::vector<double>{1, -1, 1}), std::invalid_argument);
}

// A second factorisation with other conductances and shunts solves the new system, and the
// solution may overwrite the right-hand side.
TEST(NodalSystem, RefactorisingSolvesTheNewSystem) {
  std::mt19937_64 rng(31);
  const Graph tree = random_tree(300, rng);
  const Graph ring = ring_with_chords();
  for (const Graph* graph : {&tree, &ring})
    for (const Method method : {Method::automatic, Method::sparse_cholesky}) {
      NodalSystem system(graph->nodes, graph->a, graph->b, method);
      const std::vector<double> rhs = uniform(graph->nodes, -1, 1, rng);
      const std::vector<double> g1 = log_uniform(graph->a.size(), 1e-1, 1e1, rng);
      const std::vector<double> s1 = uniform(graph->nodes, 0, 1, rng);
      const std::vector<double> g2 = log_uniform(graph->a.size(), 1, 1e1, rng);
      std::vector<double> s2(graph->nodes, 0.0);
      for (std::size_t i = 3; i < graph->nodes; i += 4) s2[i] = 4.0;
      ASSERT_LT(condition(*graph, g1, s1), 1e4);
      ASSERT_LT(condition(*graph, g2, s2), 1e4);
      EXPECT_LT(relative_difference(solved(system, g1, s1, rhs), dense_solve(*graph, g1, s1, rhs)), 1e-12);
      ASSERT_EQ(system.factorize(g2, s2), -1);
      std::vector<double> x = rhs;
      system.solve(x, x);  // in place
      EXPECT_LT(relative_difference(x, dense_solve(*graph, g2, s2, rhs)), 1e-12);
    }
}

// A released factorisation refuses solves until the next factorize, which gives the same
// bits as before the release (the tree's arrays made again, the Cholesky's kept).
TEST(NodalSystem, AReleasedFactorisationIsMadeAgainByTheNextFactorize) {
  std::mt19937_64 rng(37);
  const Graph tree = random_tree(200, rng);
  const Graph ring = ring_with_chords();
  for (const Graph* graph : {&tree, &ring}) {
    NodalSystem system(graph->nodes, graph->a, graph->b);
    const std::vector<double> rhs = uniform(graph->nodes, -1, 1, rng);
    const std::vector<double> g = log_uniform(graph->a.size(), 1e-1, 1e1, rng);
    const std::vector<double> s = uniform(graph->nodes, 0, 1, rng);
    const std::vector<double> before = solved(system, g, s, rhs);
    std::vector<double> diagonal_before(2), diagonal_after(2);
    const std::vector<std::int32_t> nodes = {1, static_cast<std::int32_t>(graph->nodes - 1)};
    system.inverse_diagonal(nodes, diagonal_before);
    system.release_factorization();
    std::vector<double> x = rhs;
    EXPECT_THROW(system.solve(x, x), std::logic_error);
    EXPECT_THROW(system.inverse_diagonal(nodes, diagonal_after), std::logic_error);
    EXPECT_EQ(solved(system, g, s, rhs), before);
    system.inverse_diagonal(nodes, diagonal_after);
    EXPECT_EQ(diagonal_after, diagonal_before);
  }
}

TEST(NodalSystem, MovesKeepTheFactorisation) {
  NodalSystem chain(3, {0, 1}, {1, 2});
  ASSERT_EQ(chain.factorize(std::vector<double>{1.0, 1.0}, std::vector<double>{0, 0, 1}), -1);
  NodalSystem moved(std::move(chain));
  std::vector<double> x{1, 0, 0};
  moved.solve(x, x);
  EXPECT_NEAR(x[0], 3.0, 1e-15);
  NodalSystem looped(2, {0, 1}, {1, 0});
  looped = std::move(moved);
  EXPECT_EQ(looped.method(), Method::tree_elimination);
  x = {0, 0, 1};
  looped.solve(x, x);
  EXPECT_NEAR(x[0], 1.0, 1e-15);
}

namespace {

// max_i |x_i - y_i| / |y_i|
double largest_relative_error(const std::vector<double>& x, const std::vector<double>& y) {
  double worst = 0;
  for (std::size_t i = 0; i < y.size(); ++i) worst = std::max(worst, std::abs(x[i] - y[i]) / std::abs(y[i]));
  return worst;
}

std::vector<double> dense_inverse_diagonal(const Graph& graph, const std::vector<double>& g,
                                           const std::vector<double>& s) {
  const Eigen::MatrixXd m = dense_matrix(graph, g, s);
  const Eigen::VectorXd d = m.llt().solve(Eigen::MatrixXd::Identity(m.rows(), m.cols())).diagonal();
  return {d.data(), d.data() + d.size()};
}

std::vector<double> inverse_diagonal(const NodalSystem& system, const std::vector<std::int32_t>& nodes) {
  std::vector<double> out(nodes.size(), -7.0);
  system.inverse_diagonal(nodes, out);
  return out;
}

std::vector<std::int32_t> every_node(std::size_t n) {
  std::vector<std::int32_t> nodes(n);
  for (std::size_t i = 0; i < n; ++i) nodes[i] = static_cast<std::int32_t>(i);
  return nodes;
}

// Shunts at about a fifth of the nodes, over two decades.
std::vector<double> some_shunts(std::size_t nodes, std::mt19937_64& rng) {
  std::vector<double> s = log_uniform(nodes, 1e-2, 1, rng);
  std::bernoulli_distribution grounded(0.2);
  for (double& x : s)
    if (!grounded(rng)) x = 0;
  s[0] = 0.5;  // at least one
  return s;
}

// Node i's own response on a tree, independently: the tree hung from i and reduced to it by
// series and parallel conductances in long double, 1 / (s_i + sum over its neighbours of the
// series conductance of the edge and the neighbour's side). O(nodes) per node.
std::vector<double> rerooted_inverse_diagonal(const Graph& tree, const std::vector<double>& g,
                                              const std::vector<double>& s) {
  std::vector<std::vector<std::pair<std::int32_t, std::size_t>>> around(tree.nodes);
  for (std::size_t e = 0; e < tree.a.size(); ++e) {
    around[static_cast<std::size_t>(tree.a[e])].emplace_back(tree.b[e], e);
    around[static_cast<std::size_t>(tree.b[e])].emplace_back(tree.a[e], e);
  }
  std::vector<double> z(tree.nodes);
  std::vector<std::int32_t> order, from(tree.nodes);
  std::vector<long double> side(tree.nodes);
  for (std::size_t root = 0; root < tree.nodes; ++root) {
    order.assign(1, static_cast<std::int32_t>(root));
    from[root] = -1;
    for (std::size_t head = 0; head < order.size(); ++head) {
      const auto v = static_cast<std::size_t>(order[head]);
      for (const auto& [w, e] : around[v])
        if (w != from[v]) {
          from[static_cast<std::size_t>(w)] = static_cast<std::int32_t>(v);
          order.push_back(w);
        }
    }
    for (std::size_t k = order.size(); k-- > 0;) {
      const auto v = static_cast<std::size_t>(order[k]);
      long double sum = s[v];
      for (const auto& [w, e] : around[v])
        if (w != from[v]) {
          const long double gw = g[e], sw = side[static_cast<std::size_t>(w)];
          sum += gw * sw / (gw + sw);
        }
      side[v] = sum;
    }
    z[root] = static_cast<double>(1.0L / side[root]);
  }
  return z;
}

}  // namespace

// Every node's own response against the diagonal of a dense inverse, on a random tree of 300
// nodes numbered from its root and not, by both methods; requested all at once, and then a
// few in another order with repeats (which the tree shares paths between). Measured 3e-14:
// the dense inverse's own rounding (condition numbers 2e3 and 5e3).
TEST(NodalSystem, TheInverseDiagonalOfATreeAgreesWithADenseInverse) {
  std::mt19937_64 rng(41);
  for (const bool shuffled : {false, true}) {
    const Graph tree = random_tree(300, rng, shuffled);
    const std::vector<double> g = log_uniform(tree.a.size(), 1e-1, 1e1, rng);
    const std::vector<double> s = some_shunts(tree.nodes, rng);
    ASSERT_LT(condition(tree, g, s), 1e4);
    const std::vector<double> exact = dense_inverse_diagonal(tree, g, s);
    const std::vector<std::int32_t> few{17, 3, 299, 17, 0, 150, 3};
    std::vector<double> exact_few;
    for (const std::int32_t i : few) exact_few.push_back(exact[static_cast<std::size_t>(i)]);
    for (const Method method : {Method::tree_elimination, Method::sparse_cholesky}) {
      NodalSystem system(tree.nodes, tree.a, tree.b, method);
      ASSERT_EQ(system.factorize(g, s), -1);
      EXPECT_LT(largest_relative_error(inverse_diagonal(system, every_node(tree.nodes)), exact), 1e-12)
          << "shuffled " << shuffled << ", method " << static_cast<int>(method);
      EXPECT_LT(largest_relative_error(inverse_diagonal(system, few), exact_few), 1e-12)
          << "shuffled " << shuffled << ", method " << static_cast<int>(method);
    }
  }
}

// Loops (a random tree with 40 chords added, and the ring): the sparse Cholesky's path.
TEST(NodalSystem, TheInverseDiagonalOfALoopedGraphAgreesWithADenseInverse) {
  std::mt19937_64 rng(43);
  Graph looped = random_tree(250, rng);
  std::uniform_int_distribution<std::int32_t> node(0, 249);
  while (looped.a.size() < 249 + 40) {
    const std::int32_t i = node(rng), j = node(rng);
    if (i == j) continue;
    looped.a.push_back(i);
    looped.b.push_back(j);
  }
  const Graph ring = ring_with_chords();
  for (const Graph* graph : {static_cast<const Graph*>(&looped), &ring}) {
    const std::vector<double> g = log_uniform(graph->a.size(), 1e-1, 1e1, rng);
    const std::vector<double> s = some_shunts(graph->nodes, rng);
    ASSERT_LT(condition(*graph, g, s), 1e4);
    NodalSystem system(graph->nodes, graph->a, graph->b);
    ASSERT_EQ(system.method(), Method::sparse_cholesky);
    ASSERT_EQ(system.factorize(g, s), -1);
    EXPECT_LT(largest_relative_error(inverse_diagonal(system, every_node(graph->nodes)),
                                     dense_inverse_diagonal(*graph, g, s)),
              1e-12)
        << graph->nodes << " nodes";
  }
}

// A tree of 3000 nodes with conductances over six decades and shunts over four (condition
// number 2.5e6) against the long-double reduction above: the selected inversion stays at
// rounding (measured 8e-16), as its terms are all positive; the sparse Cholesky subtracts and
// is off by more (measured 4e-12). A unit-vector solve agrees. A forest's two trees each have
// their own responses, by both methods.
TEST(NodalSystem, TheInverseDiagonalOfAWidelySpreadTreeIsExactToRounding) {
  std::mt19937_64 rng(47);
  const Graph tree = random_tree(3000, rng);
  const std::vector<double> g = log_uniform(tree.a.size(), 1e-3, 1e3, rng);
  const std::vector<double> s = log_uniform(tree.nodes, 1e-4, 1, rng);
  const std::vector<double> exact = rerooted_inverse_diagonal(tree, g, s);
  NodalSystem elimination(tree.nodes, tree.a, tree.b);
  NodalSystem cholesky(tree.nodes, tree.a, tree.b, Method::sparse_cholesky);
  ASSERT_EQ(elimination.method(), Method::tree_elimination);
  ASSERT_EQ(elimination.factorize(g, s), -1);
  ASSERT_EQ(cholesky.factorize(g, s), -1);
  const std::vector<double> by_elimination = inverse_diagonal(elimination, every_node(tree.nodes));
  const std::vector<double> by_cholesky = inverse_diagonal(cholesky, every_node(tree.nodes));
  // A few nodes climb their paths instead of the pass over all (which every node takes), and
  // get the same bits.
  const std::vector<std::int32_t> few{2999, 5, 1500, 2998, 5, 77, 2000, 1};
  const std::vector<double> few_by_elimination = inverse_diagonal(elimination, few);
  for (std::size_t k = 0; k < few.size(); ++k)
    EXPECT_EQ(few_by_elimination[k], by_elimination[static_cast<std::size_t>(few[k])]) << "node " << few[k];
  EXPECT_LT(largest_relative_error(by_elimination, exact), 1e-13);
  EXPECT_LT(largest_relative_error(by_cholesky, exact), 1e-10);
  for (const std::int32_t i : {0, 1, 1234, 2999}) {
    std::vector<double> x(tree.nodes, 0.0);
    x[static_cast<std::size_t>(i)] = 1;
    elimination.solve(x, x);
    EXPECT_NEAR(x[static_cast<std::size_t>(i)], exact[static_cast<std::size_t>(i)],
                1e-13 * exact[static_cast<std::size_t>(i)])
        << "node " << i;
  }

  const Graph forest{7, {2, 2, 2, 4, 5}, {0, 1, 3, 5, 6}};
  const std::vector<double> fg = uniform(forest.a.size(), 0.5, 2, rng);
  const std::vector<double> fs{0, 0, 0, 0.7, 0, 0, 1.3};
  const std::vector<double> dense = dense_inverse_diagonal(forest, fg, fs);
  for (const Method method : {Method::tree_elimination, Method::sparse_cholesky}) {
    NodalSystem system(forest.nodes, forest.a, forest.b, method);
    ASSERT_EQ(system.factorize(fg, fs), -1);
    EXPECT_LT(largest_relative_error(inverse_diagonal(system, every_node(forest.nodes)), dense), 1e-12);
  }
}

// The chain of twelve decades grounded at its far end only: node k's own response is the
// resistance from it to ground, the sum of those beyond it, which the selected inversion gets
// to rounding (its terms are all positive), whatever the spread.
TEST(NodalSystem, TheInverseDiagonalIsExactToRoundingAlongAnIllConditionedChain) {
  std::mt19937_64 rng(3);
  const std::size_t n = 1000;
  Graph chain{n, {}, {}};
  for (std::size_t k = 0; k + 1 < n; ++k) {
    chain.a.push_back(static_cast<std::int32_t>(k));
    chain.b.push_back(static_cast<std::int32_t>(k + 1));
  }
  const std::vector<double> g = log_uniform(n - 1, 1e-6, 1e6, rng);
  std::vector<double> s(n, 0.0);
  s[n - 1] = 1.0;
  NodalSystem system(chain.nodes, chain.a, chain.b);
  ASSERT_EQ(system.method(), Method::tree_elimination);
  ASSERT_EQ(system.factorize(g, s), -1);
  const std::vector<double> z = inverse_diagonal(system, every_node(n));
  long double beyond = 1;
  for (std::size_t k = n; k-- > 0;) {
    EXPECT_NEAR(z[k], static_cast<double>(beyond), 1e-12 * static_cast<double>(beyond)) << "node " << k;
    if (k > 0) beyond += 1.0L / g[k - 1];
  }
}

// Two nodes by hand: g = 2 between them, shunts 1 and 3. K = [[3, -2], [-2, 5]], det 11:
// Sigma = [[5, 2], [2, 3]] / 11. And the refusals.
TEST(NodalSystem, TheInverseDiagonalOfTwoNodesAndItsRefusals) {
  for (const Method method : {Method::tree_elimination, Method::sparse_cholesky}) {
    NodalSystem pair(2, {0}, {1}, method);
    std::vector<double> out(3);
    EXPECT_THROW(pair.inverse_diagonal(std::vector<std::int32_t>{0, 1, 1}, out), std::logic_error);
    ASSERT_EQ(pair.factorize(std::vector<double>{2.0}, std::vector<double>{1.0, 3.0}), -1);
    pair.inverse_diagonal(std::vector<std::int32_t>{1, 0, 1}, out);
    EXPECT_NEAR(out[0], 3.0 / 11, 1e-16);
    EXPECT_NEAR(out[1], 5.0 / 11, 1e-16);
    EXPECT_NEAR(out[2], 3.0 / 11, 1e-16);
    EXPECT_THROW(pair.inverse_diagonal(std::vector<std::int32_t>{0, 1}, out), std::invalid_argument);
    out.assign(2, -1.0);
    EXPECT_THROW(pair.inverse_diagonal(std::vector<std::int32_t>{0, 2}, out), std::invalid_argument);
    EXPECT_THROW(pair.inverse_diagonal(std::vector<std::int32_t>{-1, 0}, out), std::invalid_argument);
    EXPECT_EQ(out, std::vector<double>(2, -1.0));  // refused before anything is written
    pair.inverse_diagonal({}, {});                 // nothing asked
    // After a refusal the scratch is intact: the same answer again, then for a new system.
    pair.inverse_diagonal(std::vector<std::int32_t>{0, 1}, out);
    EXPECT_NEAR(out[0], 5.0 / 11, 1e-16);
    ASSERT_EQ(pair.factorize(std::vector<double>{1.0}, std::vector<double>{1.0, 0.0}), -1);
    pair.inverse_diagonal(std::vector<std::int32_t>{0, 1}, out);  // K = [[2, -1], [-1, 1]]
    EXPECT_NEAR(out[0], 1.0, 1e-15);
    EXPECT_NEAR(out[1], 2.0, 1e-15);
    // A singular factorisation leaves nothing to use.
    EXPECT_EQ(pair.factorize(std::vector<double>{1.0}, std::vector<double>{0.0, 0.0}), 0);
    EXPECT_THROW(pair.inverse_diagonal(std::vector<std::int32_t>{0, 1}, out), std::logic_error);
  }
}

// The solve in halves, as a step of the 0D vessels takes it: the forward half with the
// factorisation, a later change of the right-hand side at a few nodes through add_forward,
// the potentials at some nodes through backward_at and at all through backward; equal to a
// solve of the whole right-hand side, on a tree (both numberings) and on a looped graph.
TEST(NodalSystem, TheSolveInHalvesEqualsTheWholeSolve) {
  std::mt19937_64 rng(77);
  std::vector<Graph> graphs = {random_tree(3000, rng, false), random_tree(3000, rng, true), ring_with_chords()};
  for (std::size_t which = 0; which < graphs.size(); ++which) {
    const Graph& graph = graphs[which];
    const std::vector<double> g = log_uniform(graph.a.size(), 1e-1, 1e1, rng);
    const std::vector<double> s = uniform(graph.nodes, 1e-2, 1e-1, rng);
    const std::vector<double> rhs = uniform(graph.nodes, -1, 1, rng);
    const std::vector<std::int32_t> late = {0, static_cast<std::int32_t>(graph.nodes / 2), 3, 0};
    const std::vector<double> change = {0.5, -0.25, 2.0, 0.125};
    std::vector<double> whole = rhs;
    for (std::size_t k = 0; k < late.size(); ++k) whole[static_cast<std::size_t>(late[k])] += change[k];
    for (const Method method : {Method::automatic, Method::sparse_cholesky}) {
      NodalSystem system(graph.nodes, graph.a, graph.b, method);
      const std::vector<double> reference = solved(system, g, s, whole);
      const std::vector<double> before = solved(system, g, s, rhs);
      std::vector<double> y = rhs;
      ASSERT_EQ(system.factorize_forward(g, s, y), -1);
      const std::vector<std::int32_t> asked = {late[1], late[2], 1};
      std::vector<double> early(asked.size());
      system.backward_at(asked, y, early);
      for (std::size_t k = 0; k < asked.size(); ++k)
        EXPECT_NEAR(early[k], before[static_cast<std::size_t>(asked[k])], 1e-13 * std::abs(before[static_cast<std::size_t>(asked[k])]) + 1e-15)
            << "graph " << which << " node " << asked[k];
      system.add_forward(late, change, y);
      std::vector<double> x(graph.nodes);
      system.backward(y, x);
      EXPECT_LT(relative_difference(x, reference), 1e-12) << "graph " << which;
      std::vector<double> z = whole;
      system.forward(z);
      system.backward(z, z);
      EXPECT_LT(relative_difference(z, reference), 1e-12) << "graph " << which;
    }
  }
}

// Past 2^16 nodes the tree's sweeps run subtrees in parallel; the pivots still sum their
// children in one thread's order, so two threads give the bits of one.
TEST(NodalSystem, TwoThreadsEliminateATreeToTheBitsOfOne) {
  std::mt19937_64 rng(5);
  for (const bool shuffled : {false, true}) {
    const Graph tree = random_tree(200000, rng, shuffled);
    const std::vector<double> g = log_uniform(tree.a.size(), 1e-2, 1e2, rng);
    const std::vector<double> s = uniform(tree.nodes, 1e-4, 1e-3, rng);
    const std::vector<double> rhs = uniform(tree.nodes, -1, 1, rng);
    NodalSystem one(tree.nodes, tree.a, tree.b), two(tree.nodes, tree.a, tree.b);
    two.set_threads(2);
    std::vector<double> y1 = rhs, y2 = rhs;
    ASSERT_EQ(one.factorize_forward(g, s, y1), -1);
    ASSERT_EQ(two.factorize_forward(g, s, y2), -1);
    EXPECT_EQ(y1, y2) << "shuffled " << shuffled;
    one.backward(y1, y1);
    two.backward(y2, y2);
    EXPECT_EQ(y1, y2) << "shuffled " << shuffled;
    std::vector<double> x1(tree.nodes), x2(tree.nodes);
    one.solve(rhs, x1);
    two.solve(rhs, x2);
    EXPECT_EQ(x1, x2);
    EXPECT_EQ(x1, y1);
    // And a bad conductance is named as one thread names it.
    std::vector<double> bad = g;
    bad[tree.a.size() / 3] = -1;
    std::string one_message, two_message;
    try { one.factorize(bad, s); } catch (const std::invalid_argument& e) { one_message = e.what(); }
    try { two.factorize(bad, s); } catch (const std::invalid_argument& e) { two_message = e.what(); }
    EXPECT_FALSE(one_message.empty());
    EXPECT_EQ(one_message, two_message);
  }
}

// Opened edges cut a tree into the part above them and the subtrees below, each subtree's
// root held open: given the whole system's potentials at those roots, every node below them
// gets the whole's bits (its subtree is eliminated alike), on one thread or two.
TEST(NodalSystem, OpenedEdgesLeaveTheSubtreesBelowThemTheWholesBits) {
  std::mt19937_64 rng(23);
  for (const std::size_t n : {std::size_t{3000}, std::size_t{200000}})
    for (const bool shuffled : {false, true}) {
      const Graph tree = random_tree(n, rng, shuffled);
      const std::vector<double> g = log_uniform(tree.a.size(), 1e-2, 1e2, rng);
      const std::vector<double> s = uniform(tree.nodes, 1e-4, 1e-3, rng);
      const std::vector<double> rhs = uniform(tree.nodes, -1, 1, rng);
      NodalSystem whole(tree.nodes, tree.a, tree.b);
      std::vector<double> x(n);
      ASSERT_EQ(whole.factorize(g, s), -1);
      whole.solve(rhs, x);
      // Twenty edges opened, none twice.
      std::vector<std::int32_t> parent(n, -1), opened;
      for (std::size_t e = 0; e < tree.a.size(); ++e) {
        parent[static_cast<std::size_t>(tree.b[e])] = tree.a[e];
      }
      std::vector<unsigned char> cut_below(n, 0);
      std::uniform_int_distribution<std::int32_t> any_edge(0, static_cast<std::int32_t>(tree.a.size()) - 1);
      // As shares hang from a top: no opened edge below another.
      auto above_or_below_a_cut = [&](std::int32_t c) {
        for (std::int32_t k = c; k >= 0; k = parent[static_cast<std::size_t>(k)])
          if (cut_below[static_cast<std::size_t>(k)]) return true;
        for (std::size_t d = 0; d < n; ++d)
          if (cut_below[d])
            for (std::int32_t k = static_cast<std::int32_t>(d); k >= 0; k = parent[static_cast<std::size_t>(k)])
              if (k == c) return true;
        return false;
      };
      while (opened.size() < 20) {
        const std::int32_t e = any_edge(rng);
        if (above_or_below_a_cut(tree.b[static_cast<std::size_t>(e)])) continue;
        opened.push_back(e);
        cut_below[static_cast<std::size_t>(tree.b[static_cast<std::size_t>(e)])] = 1;
      }
      for (const int threads : {1, 2}) {
        NodalSystem open(tree.nodes, tree.a, tree.b);
        open.set_threads(threads);
        open.open_edges(opened);
        EXPECT_TRUE(open.roots_open());
        std::vector<double> y = rhs, bad_g = g;
        for (const std::int32_t e : opened) bad_g[static_cast<std::size_t>(e)] = -1;  // not read
        open.factorize_forward(bad_g, s, y);
        for (std::size_t c = 0; c < n; ++c)
          if (cut_below[c] || parent[c] < 0) y[c] = x[c];
        open.backward(y, y);
        std::size_t checked = 0;
        for (std::size_t c = 0; c < n; ++c) {
          bool below = false;
          for (std::int32_t k = static_cast<std::int32_t>(c); k >= 0 && !below; k = parent[static_cast<std::size_t>(k)])
            below = cut_below[static_cast<std::size_t>(k)] != 0;
          if (!below) continue;
          ++checked;
          ASSERT_EQ(y[c], x[c]) << "node " << c << " of " << n << ", threads " << threads;
        }
        EXPECT_GE(checked, 20u);
      }
    }
  NodalSystem chain(3, {0, 1}, {1, 2});
  EXPECT_THROW(chain.open_edges(std::vector<std::int32_t>{2}), std::invalid_argument);
  NodalSystem again(3, {0, 1}, {1, 2});
  EXPECT_THROW(again.open_edges(std::vector<std::int32_t>{1, 1}), std::invalid_argument);
}

namespace hemotree {
namespace {

// A random tree relabelled depth first, each node's edge numbered one below it: every
// subtree is a run of consecutive nodes, as the 0D vessels' subtree order makes them, so the
// system keeps neither an order, nor task lists, nor parent edges. It must solve as the same
// tree under other labels does, and give one thread's bits with two.
TEST(NodalSystem, ATreeNumberedDepthFirstSolvesAsUnderAnyOtherLabels) {
  std::mt19937_64 rng(11);
  const std::size_t n = 200000;
  const Graph grown = random_tree(n, rng, false);  // edge k - 1 hangs node k from grown.a[k - 1]
  std::vector<std::vector<std::int32_t>> children(n);
  for (std::size_t e = 0; e < grown.a.size(); ++e) children[static_cast<std::size_t>(grown.a[e])].push_back(grown.b[e]);
  std::vector<std::int32_t> label(n, -1), stack = {0};
  std::int32_t next = 0;
  while (!stack.empty()) {
    const std::int32_t k = stack.back();
    stack.pop_back();
    label[static_cast<std::size_t>(k)] = next++;
    for (auto c = children[static_cast<std::size_t>(k)].rbegin(); c != children[static_cast<std::size_t>(k)].rend(); ++c)
      stack.push_back(*c);
  }
  Graph depth_first{n, std::vector<std::int32_t>(n - 1), std::vector<std::int32_t>(n - 1)};
  std::vector<std::size_t> edge_of(n - 1);  // grown's edge for each depth-first edge
  for (std::size_t e = 0; e < grown.a.size(); ++e) {
    const auto child = static_cast<std::size_t>(label[static_cast<std::size_t>(grown.b[e])]);
    depth_first.a[child - 1] = label[static_cast<std::size_t>(grown.a[e])];
    depth_first.b[child - 1] = static_cast<std::int32_t>(child);
    edge_of[child - 1] = e;
  }
  const std::vector<double> g_grown = log_uniform(grown.a.size(), 1e-2, 1e2, rng);
  const std::vector<double> s_grown = uniform(n, 1e-4, 1e-3, rng);
  const std::vector<double> b_grown = uniform(n, -1, 1, rng);
  std::vector<double> g(n - 1), s(n), b(n);
  for (std::size_t e = 0; e + 1 < n; ++e) g[e] = g_grown[edge_of[e]];
  for (std::size_t k = 0; k < n; ++k) {
    s[static_cast<std::size_t>(label[k])] = s_grown[k];
    b[static_cast<std::size_t>(label[k])] = b_grown[k];
  }
  NodalSystem reference(n, grown.a, grown.b), one(n, depth_first.a, depth_first.b), two(n, depth_first.a, depth_first.b);
  two.set_threads(2);
  const std::vector<double> x_grown = solved(reference, g_grown, s_grown, b_grown);
  const std::vector<double> x1 = solved(one, g, s, b), x2 = solved(two, g, s, b);
  EXPECT_EQ(x1, x2);
  std::vector<double> relabelled(n);
  for (std::size_t k = 0; k < n; ++k) relabelled[static_cast<std::size_t>(label[k])] = x_grown[k];
  EXPECT_LT(relative_difference(x1, relabelled), 1e-12);
  // A bad conductance is named by the edge's own number.
  std::vector<double> bad = g;
  bad[n / 3] = -1;
  try {
    two.factorize(bad, s);
    ADD_FAILURE() << "a negative conductance was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("conductance of edge " + std::to_string(n / 3) + " "), std::string::npos) << e.what();
  }
}

// Shunts written into the system's own workspace factorise as shunts given apart, to the bit,
// on a tree (where the workspace is the pivots' array) and on a looped graph.
TEST(NodalSystem, ShuntsInTheWorkspaceFactoriseAsShuntsGivenApart) {
  std::mt19937_64 rng(3);
  for (const Graph& graph : {random_tree(5000, rng, false), random_tree(5000, rng, true), ring_with_chords()}) {
    const std::vector<double> g = log_uniform(graph.a.size(), 1e-1, 1e1, rng);
    const std::vector<double> s = uniform(graph.nodes, 1e-2, 1e-1, rng);
    const std::vector<double> rhs = uniform(graph.nodes, -1, 1, rng);
    NodalSystem apart(graph.nodes, graph.a, graph.b), in_place(graph.nodes, graph.a, graph.b);
    std::vector<double> y_apart = rhs, y_in_place = rhs;
    ASSERT_EQ(apart.factorize_forward(g, s, y_apart), -1);
    for (int round = 0; round < 2; ++round) {  // the second after a release
      const std::span<double> w = in_place.shunt_workspace();
      ASSERT_EQ(w.size(), graph.nodes);
      std::copy(s.begin(), s.end(), w.begin());
      y_in_place = rhs;
      ASSERT_EQ(in_place.factorize_forward_in_place(g, y_in_place), -1);
      EXPECT_EQ(y_in_place, y_apart);
      std::vector<double> x_apart(graph.nodes), x_in_place(graph.nodes);
      apart.backward(y_apart, x_apart);
      in_place.backward(y_in_place, x_in_place);
      EXPECT_EQ(x_in_place, x_apart);
      in_place.release_factorization();
    }
    // A bad shunt is refused, though its value is gone.
    const std::span<double> w = in_place.shunt_workspace();
    std::copy(s.begin(), s.end(), w.begin());
    w[graph.nodes / 2] = -1;
    y_in_place = rhs;
    EXPECT_THROW(in_place.factorize_forward_in_place(g, y_in_place), std::invalid_argument);
  }
}

}  // namespace
}  // namespace hemotree
