// FlowNetwork (network_flow/flow_network.hpp) against a dense solve of Kirchhoff's laws on
// every node, prescribed pressures as identity rows: an independent assembly of the same
// equations, on trees and on looped graphs.
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "network_flow/flow_network.hpp"

using namespace hemotree;

namespace {

struct Case {
  std::size_t nodes = 0;
  std::vector<std::int32_t> a, b;
  std::vector<double> conductance, shunt, inflow, pressure;
  std::vector<unsigned char> prescribed;
};

// A random connected graph: a random tree, then `extra` chords (loops), both orientations.
Case random_case(std::size_t nodes, std::size_t extra, std::size_t prescribed_count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0, 1);
  Case c;
  c.nodes = nodes;
  auto edge = [&](std::int32_t i, std::int32_t j) {
    if (unit(rng) < 0.5) std::swap(i, j);
    c.a.push_back(i);
    c.b.push_back(j);
    c.conductance.push_back(std::pow(10.0, -12 + 4 * unit(rng)));  // spread like vessels' 1/R
  };
  for (std::size_t i = 1; i < nodes; ++i)
    edge(static_cast<std::int32_t>(i), static_cast<std::int32_t>(rng() % i));
  for (std::size_t k = 0; k < extra; ++k) {
    const auto i = static_cast<std::int32_t>(rng() % nodes), j = static_cast<std::int32_t>(rng() % nodes);
    if (i != j) edge(i, j);
  }
  c.shunt.assign(nodes, 0.0);
  c.inflow.assign(nodes, 0.0);
  c.pressure.assign(nodes, 0.0);
  c.prescribed.assign(nodes, 0);
  for (std::size_t k = 0; k < prescribed_count; ++k) {
    const std::size_t i = rng() % nodes;
    c.prescribed[i] = 1;
    c.pressure[i] = 1000 + 4000 * unit(rng);
  }
  for (std::size_t i = 0; i < nodes; ++i) {
    if (unit(rng) < 0.1) c.inflow[i] = 1e-9 * (unit(rng) - 0.3);
    if (unit(rng) < 0.05) {
      c.shunt[i] = 1e-11;
      c.inflow[i] += 1e-11 * 500;  // an outlet to 500 Pa
    }
  }
  return c;
}

// Every node's row: KCL at free nodes, p_i = given at prescribed ones.
Eigen::VectorXd dense_solution(const Case& c) {
  const auto n = static_cast<Eigen::Index>(c.nodes);
  Eigen::MatrixXd k = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
  for (std::size_t e = 0; e < c.a.size(); ++e) {
    const Eigen::Index i = c.a[e], j = c.b[e];
    const double g = c.conductance[e];
    k(i, i) += g;
    k(j, j) += g;
    k(i, j) -= g;
    k(j, i) -= g;
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    k(i, i) += c.shunt[static_cast<std::size_t>(i)];
    rhs(i) = c.inflow[static_cast<std::size_t>(i)];
    if (c.prescribed[static_cast<std::size_t>(i)]) {
      k.row(i).setZero();
      k(i, i) = 1;
      rhs(i) = c.pressure[static_cast<std::size_t>(i)];
    }
  }
  return k.fullPivLu().solve(rhs);
}

void expect_agreement(const Case& c) {
  FlowNetwork network(c.nodes, c.a, c.b, c.prescribed);
  ASSERT_EQ(network.factorize(c.conductance, c.shunt), -1);
  std::vector<double> p = c.pressure;
  network.solve(c.inflow, p);
  const Eigen::VectorXd expected = dense_solution(c);
  const double scale = expected.cwiseAbs().maxCoeff();
  for (std::size_t i = 0; i < c.nodes; ++i)
    EXPECT_NEAR(p[i], expected(static_cast<Eigen::Index>(i)), 1e-9 * scale) << "node " << i;
  // Kirchhoff's current law at every free node, from the edge flows.
  std::vector<double> q(c.a.size()), net_out(c.nodes, 0.0);
  network.edge_flows(p, q);
  double largest = 0;
  for (std::size_t e = 0; e < q.size(); ++e) {
    net_out[static_cast<std::size_t>(c.a[e])] += q[e];
    net_out[static_cast<std::size_t>(c.b[e])] -= q[e];
    largest = std::max(largest, std::abs(q[e]));
  }
  for (std::size_t i = 0; i < c.nodes; ++i) {
    if (c.prescribed[i]) continue;
    EXPECT_NEAR(net_out[i] + c.shunt[i] * p[i], c.inflow[i], 1e-9 * largest) << "node " << i;
  }
}

}  // namespace

TEST(FlowNetwork, TreeWithPrescribedPressuresMatchesTheDenseSolve) {
  for (unsigned seed : {1u, 2u, 3u}) expect_agreement(random_case(200, 0, 3, seed));
}

TEST(FlowNetwork, LoopedGraphMatchesTheDenseSolve) {
  for (unsigned seed : {4u, 5u, 6u}) {
    const Case c = random_case(300, 60, 4, seed);
    EXPECT_EQ(FlowNetwork(c.nodes, c.a, c.b, c.prescribed).method(), NodalSystem::Method::sparse_cholesky);
    expect_agreement(c);
  }
}

// No pressure prescribed (a tree's inflow and outlets' shunts): the free system is the
// network itself, taken without index lists or copies; the same numbers, to the bit, as the
// nodal system given the graph directly.
TEST(FlowNetwork, NothingPrescribedIsTheNodalSystemItself) {
  for (const std::size_t extra : {std::size_t{0}, std::size_t{60}}) {
    const Case c = random_case(300, extra, 0, 7);
    expect_agreement(c);
    FlowNetwork network(c.nodes, c.a, c.b, c.prescribed);
    EXPECT_EQ(network.free_node_count(), c.nodes);
    ASSERT_EQ(network.factorize(c.conductance, c.shunt), -1);
    std::vector<double> p(c.nodes);
    network.solve(c.inflow, p);
    NodalSystem direct(c.nodes, c.a, c.b);
    ASSERT_EQ(direct.factorize(c.conductance, c.shunt), -1);
    std::vector<double> x(c.nodes);
    direct.solve(c.inflow, x);
    EXPECT_EQ(p, x) << extra << " chords";
  }
  // A part with no shunt is named by its lowest node here too.
  const std::vector<std::int32_t> a{0, 2, 3}, b{1, 3, 4};
  FlowNetwork network(5, a, b, std::vector<unsigned char>(5, 0));
  std::vector<double> shunt(5, 0.0);
  shunt[0] = 0.5;
  EXPECT_EQ(network.factorize(std::vector<double>{1, 1, 1}, shunt), 2);
  EXPECT_THROW(FlowNetwork(3, std::vector<std::int32_t>{0, 1}, std::vector<std::int32_t>{1, 1},
                           std::vector<unsigned char>(3, 0)),
               std::invalid_argument);  // an edge from a node to itself
}

// Two prescribed nodes joined by one edge: its flow follows from them alone.
TEST(FlowNetwork, EdgeBetweenPrescribedNodes) {
  const std::vector<std::int32_t> a{0, 1}, b{1, 2};
  const std::vector<unsigned char> prescribed{1, 1, 0};
  FlowNetwork network(3, a, b, prescribed);
  EXPECT_EQ(network.free_node_count(), 1u);
  ASSERT_EQ(network.factorize(std::vector<double>{2.0, 1.0}, std::vector<double>{0, 0, 0}), -1);
  std::vector<double> p{10, 4, 0};
  network.solve(std::vector<double>{0, 0, 1.5}, p);  // 1.5 into node 2 flows back to node 1
  EXPECT_DOUBLE_EQ(p[2], 5.5);
  std::vector<double> q(2);
  network.edge_flows(p, q);
  EXPECT_DOUBLE_EQ(q[0], 12.0);
  EXPECT_DOUBLE_EQ(q[1], -1.5);
}

// A part with neither a prescribed pressure nor a shunt is named by its lowest node.
TEST(FlowNetwork, NamesAFloatingPart) {
  const std::vector<std::int32_t> a{0, 2, 3}, b{1, 3, 4};
  const std::vector<unsigned char> prescribed{1, 0, 0, 0, 0};
  FlowNetwork network(5, a, b, prescribed);
  EXPECT_EQ(network.factorize(std::vector<double>{1, 1, 1}, std::vector<double>(5, 0.0)), 2);
  std::vector<double> shunt(5, 0.0);
  shunt[4] = 0.5;
  EXPECT_EQ(network.factorize(std::vector<double>{1, 1, 1}, shunt), -1);
}
