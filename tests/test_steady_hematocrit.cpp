// The steady red-cell distribution (steady/steady_hematocrit.hpp): hematocrits from given
// flows against the laws applied by hand, red-cell conservation at every node of a looped
// network fed at several hematocrits, symmetry, and the coupled flow-hematocrit iteration
// checked for self-consistency (its flows solve Kirchhoff's laws with the viscosities of its
// own hematocrits, typed anew here) and run on the rat mesentery (skipped without
// ../shared/networks).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "exchange/secomb.hpp"
#include "tests/shared_networks.hpp"
#include "network_builders.hpp"
#include "physics/phase_separation.hpp"
#include "physics/rheology.hpp"
#include "steady/steady_hematocrit.hpp"

using namespace hemotree;
using test_networks::flow_boundary;
using test_networks::pressure_boundary;
namespace fs = std::filesystem;

namespace {

void add_vessels(Network& net, int nodes, const std::vector<std::pair<int, int>>& ends,
                 const std::vector<double>& diameters, double length = 1e-3) {
  for (int n = 0; n < nodes; ++n) net.add_node(n);
  for (std::size_t v = 0; v < ends.size(); ++v)
    net.add_vessel(static_cast<std::int64_t>(v), ends[v].first, ends[v].second, length, diameters[v],
                   0.1 * diameters[v], 1e6, 0);
}

NodeBoundary with_hematocrit(NodeBoundary b, double h) {
  b.hematocrit = h;
  return b;
}

void sort_boundaries(Network& net) {
  std::sort(net.boundaries.begin(), net.boundaries.end(),
            [](const NodeBoundary& a, const NodeBoundary& b) { return a.node < b.node; });
}

Blood rat_blood() {
  Blood blood;
  blood.hematocrit = 0.45;
  blood.plasma_viscosity = 1.0466e-3;
  blood.mean_cell_volume = 55e-18;
  return blood;
}

// Red cells entering minus leaving node n: vessels, and the node's boundary supplying the
// vessels' surplus at its hematocrit or taking their deficit at the mix of what enters.
double red_cell_imbalance(const Network& net, std::span<const double> q, const std::vector<double>& h, int n,
                          double boundary_h, bool has_boundary) {
  double in_q = 0, in_cells = 0, out_q = 0, out_cells = 0;
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    const bool leaves = (q[v] > 0 && net.from[v] == n) || (q[v] < 0 && net.to[v] == n);
    const bool enters = (q[v] > 0 && net.to[v] == n) || (q[v] < 0 && net.from[v] == n);
    if (enters) in_q += std::abs(q[v]), in_cells += std::abs(q[v]) * h[v];
    if (leaves) out_q += std::abs(q[v]), out_cells += std::abs(q[v]) * h[v];
  }
  if (has_boundary && out_q > in_q) in_cells += (out_q - in_q) * boundary_h, in_q = out_q;
  if (has_boundary && in_q > out_q) out_cells += (in_q - out_q) * in_cells / in_q;
  return in_cells - out_cells;
}

}  // namespace

// One feed (20 um) dividing 2 : 1 into 15 um and 10 um daughters, the second written against
// its flow; the feed takes the inflow's hematocrit, the daughters the law's.
TEST(DistributeHematocrit, SingleBifurcationFollowsTheLaw) {
  Network net;
  add_vessels(net, 4, {{0, 1}, {1, 2}, {3, 1}}, {20e-6, 15e-6, 10e-6});
  net.boundaries = {with_hematocrit(flow_boundary(0, 3e-12), 0.45), pressure_boundary(2, 0), pressure_boundary(3, 0)};
  const std::vector<double> q = {3e-12, 2e-12, -1e-12};
  const std::vector<double> h = distribute_hematocrit(net, q, 0.4, 1.2);
  Bifurcation bif{20e-6, 15e-6, 10e-6, 2.0 / 3.0, 0.45, 1.2};
  const DaughterHematocrits d = daughter_hematocrits(bif);
  EXPECT_DOUBLE_EQ(h[0], 0.45);
  EXPECT_DOUBLE_EQ(h[1], d.first);
  EXPECT_DOUBLE_EQ(h[2], d.second);
  EXPECT_GT(h[1], 0.45);  // the wider, faster daughter draws more than its share of cells
  EXPECT_NEAR(2 * h[1] + h[2], 3 * 0.45, 1e-14);
  // The default hematocrit where the boundary gives none.
  net.boundaries[0].hematocrit = std::numeric_limits<double>::quiet_NaN();
  EXPECT_DOUBLE_EQ(distribute_hematocrit(net, q, 0.4, 1.2)[0], 0.4);
}

// 2 and 1 (x1e-12 m^3/s) at 0.45 and 0.30 meet: 0.4 leaves; a stagnant vessel carries plasma.
TEST(DistributeHematocrit, ConvergingNodeMixesByFlux) {
  Network net;
  add_vessels(net, 5, {{0, 2}, {1, 2}, {2, 3}, {2, 4}}, {10e-6, 10e-6, 12e-6, 8e-6});
  net.boundaries = {with_hematocrit(flow_boundary(0, 2e-12), 0.45), with_hematocrit(flow_boundary(1, 1e-12), 0.30),
                    pressure_boundary(3, 0), pressure_boundary(4, 0)};
  const std::vector<double> h = distribute_hematocrit(net, std::vector<double>{2e-12, 1e-12, 3e-12, 0.0}, 0.45, 1);
  EXPECT_NEAR(h[2], 0.4, 1e-15);
  EXPECT_EQ(h[3], 0.0);
}

// No separation where the law does not apply (NetFlow's dishem.cpp): two inflows feeding two
// vessels, a boundary at a dividing node, one vessel feeding three: every outflow takes the mix.
TEST(DistributeHematocrit, MixesWhereTheLawDoesNotApply) {
  Network two_in;
  add_vessels(two_in, 5, {{0, 2}, {1, 2}, {2, 3}, {2, 4}}, {10e-6, 10e-6, 12e-6, 6e-6});
  two_in.boundaries = {with_hematocrit(flow_boundary(0, 1e-12), 0.5), with_hematocrit(flow_boundary(1, 1e-12), 0.3),
                       pressure_boundary(3, 0), pressure_boundary(4, 0)};
  auto h = distribute_hematocrit(two_in, std::vector<double>{1e-12, 1e-12, 1.8e-12, 0.2e-12}, 0.45, 1);
  EXPECT_NEAR(h[2], 0.4, 1e-15);
  EXPECT_NEAR(h[3], 0.4, 1e-15);

  Network fed_node;  // 0 -> 1 -> {2, 3}, and 1 also receives 1e-12 at 0.2 through a boundary
  add_vessels(fed_node, 4, {{0, 1}, {1, 2}, {1, 3}}, {10e-6, 12e-6, 6e-6});
  fed_node.boundaries = {with_hematocrit(flow_boundary(0, 1e-12), 0.5), with_hematocrit(flow_boundary(1, 1e-12), 0.2),
                         pressure_boundary(2, 0), pressure_boundary(3, 0)};
  h = distribute_hematocrit(fed_node, std::vector<double>{1e-12, 1.8e-12, 0.2e-12}, 0.45, 1);
  EXPECT_NEAR(h[1], 0.35, 1e-15);
  EXPECT_NEAR(h[2], 0.35, 1e-15);

  Network three;
  add_vessels(three, 5, {{0, 1}, {1, 2}, {1, 3}, {1, 4}}, {10e-6, 8e-6, 6e-6, 4e-6});
  three.boundaries = {with_hematocrit(flow_boundary(0, 1e-12), 0.45), pressure_boundary(2, 0), pressure_boundary(3, 0),
                      pressure_boundary(4, 0)};
  h = distribute_hematocrit(three, std::vector<double>{1e-12, 0.7e-12, 0.2e-12, 0.1e-12}, 0.45, 1);
  for (int v : {1, 2, 3}) EXPECT_DOUBLE_EQ(h[v], 0.45) << "vessel " << v;
}

// The ladder of test_steady_flow (rails 0-1-2-3 and 4-5-6-7, rungs) fed at nodes 0 and 3 and
// possibly 4 (a pressure) at three hematocrits: red cells balance at every node.
TEST(DistributeHematocrit, ConservesRedCellsOnALoopedNetwork) {
  Network net;
  std::vector<std::pair<int, int>> ends;
  for (int i = 0; i < 3; ++i) ends.emplace_back(i, i + 1);
  for (int i = 4; i < 7; ++i) ends.emplace_back(i + 1, i);
  for (int i = 0; i < 4; ++i) ends.emplace_back(i, i + 4);
  add_vessels(net, 8, ends, {20e-6, 18e-6, 16e-6, 20e-6, 18e-6, 16e-6, 9e-6, 8e-6, 7e-6, 6e-6});
  net.boundaries = {with_hematocrit(flow_boundary(0, 2e-12), 0.45), with_hematocrit(flow_boundary(3, 1e-12), 0.30),
                    with_hematocrit(pressure_boundary(4, 100.0), 0.2), flow_boundary(5, -0.5e-12),
                    pressure_boundary(7, 50.0)};
  sort_boundaries(net);
  std::vector<double> r(net.vessel_count());
  for (std::size_t v = 0; v < r.size(); ++v) r[v] = 1e14 * (1 + 0.3 * static_cast<double>(v));
  const SteadyFlow s = solve_steady_flow(net, r, 0.0);
  const std::vector<double> h = distribute_hematocrit(net, s.flow, 0.42, 1);
  const double boundary_h[] = {0.45, 0, 0, 0.30, 0.2, 0.42, 0, 0.42};
  const bool has_boundary[] = {true, false, false, true, true, true, false, true};
  double cells_in = 0;
  for (int n = 0; n < 8; ++n) {
    EXPECT_NEAR(red_cell_imbalance(net, s.flow, h, n, boundary_h[n], has_boundary[n]), 0.0, 1e-14 * 1e-12)
        << "node " << n;
  }
  for (double x : h) {
    EXPECT_GE(x, 0.0);
    EXPECT_LT(x, 1.0);
    cells_in += x;
  }
  EXPECT_GT(cells_in, 0);
  // At least one interior node divides its feed, and there the daughters differ.
  int separating = 0;
  for (int n : {1, 2, 6}) {
    std::vector<std::size_t> out;
    for (std::size_t v = 0; v < net.vessel_count(); ++v)
      if ((s.flow[v] > 0 && net.from[v] == n) || (s.flow[v] < 0 && net.to[v] == n)) out.push_back(v);
    if (out.size() == 2 && h[out[0]] != h[out[1]]) ++separating;
  }
  EXPECT_GE(separating, 1);
}

TEST(DistributeHematocrit, RefusesCyclesAndMismatchedFlows) {
  Network net;
  add_vessels(net, 3, {{0, 1}, {1, 2}, {2, 0}}, {10e-6, 10e-6, 10e-6});
  net.boundaries = {pressure_boundary(0, 0)};
  try {
    distribute_hematocrit(net, std::vector<double>{1e-12, 1e-12, 1e-12}, 0.45, 1);
    ADD_FAILURE() << "a circulating flow was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("directed cycle"), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).rfind("vessel ", 0), 0u) << e.what();
  }
  EXPECT_THROW(distribute_hematocrit(net, std::vector<double>{1e-12}, 0.45, 1), InputError);
  EXPECT_THROW(distribute_hematocrit(net, std::vector<double>{1e-12, NAN, 0}, 0.45, 1), InputError);
}

// A mirror-symmetric two-level tree with unequal daughters at the second level: the coupled
// solution is mirror-symmetric, and the narrow daughters get fewer cells.
TEST(SteadyWithPhaseSeparation, SymmetricNetworkGivesSymmetricHematocrits) {
  Network net;
  add_vessels(net, 8, {{0, 1}, {1, 2}, {1, 3}, {2, 4}, {2, 5}, {3, 6}, {3, 7}},
              {20e-6, 14e-6, 14e-6, 10e-6, 6e-6, 10e-6, 6e-6});
  net.boundaries = {with_hematocrit(flow_boundary(0, 1e-12), 0.45)};
  for (int n = 4; n < 8; ++n) net.boundaries.push_back(pressure_boundary(n, 1000));
  const SteadyHematocritResult res = solve_steady_with_phase_separation(net, rat_blood(), 200, 1e-12, 1.0);
  ASSERT_TRUE(res.converged) << res.change;
  const auto& h = res.hematocrit;
  EXPECT_NEAR(h[1], h[2], 1e-13);
  EXPECT_NEAR(h[3], h[5], 1e-13);
  EXPECT_NEAR(h[4], h[6], 1e-13);
  EXPECT_NEAR(h[1], 0.45, 1e-13);  // an even split of a symmetric pair leaves H_F
  EXPECT_LT(h[4], h[3]);
  EXPECT_NEAR(res.flow.flow[3] * h[3] + res.flow.flow[4] * h[4], res.flow.flow[1] * h[1], 1e-15 * 1e-12);
}

// The bridged diamond (flow into 0, pressure at 3) in microvessels: the iteration converges,
// its hematocrits are those its flows give, and its flows solve Kirchhoff's laws with
// Poiseuille resistances at its own hematocrits, typed anew.
TEST(SteadyWithPhaseSeparation, CoupledSolutionIsSelfConsistent) {
  Network net;
  const std::vector<double> d = {12e-6, 9e-6, 8e-6, 11e-6, 5e-6};
  add_vessels(net, 4, {{0, 1}, {0, 2}, {1, 3}, {3, 2}, {1, 2}}, d, 5e-4);
  net.boundaries = {with_hematocrit(flow_boundary(0, 2e-12), 0.45), pressure_boundary(3, 2000)};
  const Blood blood = rat_blood();
  const double tol = 1e-11;
  const SteadyHematocritResult res = solve_steady_with_phase_separation(net, blood, 500, tol, 0.7);
  ASSERT_TRUE(res.converged) << res.change;
  EXPECT_LT(res.change, tol);
  EXPECT_GT(res.iterations, 2);
  const auto& q = res.flow.flow;
  const auto& p = res.flow.node_pressure;
  EXPECT_EQ(res.hematocrit, distribute_hematocrit(net, q, blood.hematocrit, 1));
  double dp_scale = 0;
  for (std::size_t v = 0; v < d.size(); ++v) dp_scale = std::max(dp_scale, std::abs(p[net.from[v]] - p[net.to[v]]));
  for (std::size_t v = 0; v < d.size(); ++v) {
    const double mu = blood.plasma_viscosity *
                      pries_relative_viscosity(d[v] * std::cbrt(92.0 / 55.0), res.hematocrit[v]);
    const double r = 128 * mu * net.length[v] / (std::numbers::pi * std::pow(d[v], 4));
    EXPECT_NEAR(q[v] * r, p[net.from[v]] - p[net.to[v]], 10 * tol * dp_scale) << "vessel " << v;
  }
  // Mass at the interior nodes, and the vessels' hematocrits differ from the inflow's.
  for (int n : {1, 2}) {
    double net_out = 0;
    for (std::size_t v = 0; v < d.size(); ++v) net_out += (net.from[v] == n ? q[v] : 0) - (net.to[v] == n ? q[v] : 0);
    EXPECT_NEAR(net_out, 0, 1e-13 * 2e-12) << "node " << n;
  }
  EXPECT_NE(res.hematocrit[2], 0.45);
  EXPECT_THROW(solve_steady_with_phase_separation(net, blood, 10, tol, 0.0), InputError);
  EXPECT_THROW(solve_steady_with_phase_separation(net, blood, 0, tol, 0.5), InputError);
}

// An iteration stopped early says so.
TEST(SteadyWithPhaseSeparation, ReportsNonConvergence) {
  Network net;
  add_vessels(net, 4, {{0, 1}, {0, 2}, {1, 3}, {3, 2}, {1, 2}}, {12e-6, 9e-6, 8e-6, 11e-6, 5e-6}, 5e-4);
  net.boundaries = {with_hematocrit(flow_boundary(0, 2e-12), 0.45), pressure_boundary(3, 2000)};
  const SteadyHematocritResult res = solve_steady_with_phase_separation(net, rat_blood(), 2, 1e-14, 0.1);
  EXPECT_FALSE(res.converged);
  EXPECT_EQ(res.iterations, 2);
  EXPECT_GE(res.change, 1e-14);
}

// The rat mesentery as NetFlow runs it: the file's boundary hematocrits, plasma 1.0466 mPa s,
// rat cells (55 fl) in the viscosity law and in phase separation (scale 1 there, as NetFlow).
TEST(SteadyWithPhaseSeparation, RatMesenteryConverges) {
  const fs::path path = shared_mesentery();
  if (!fs::exists(path)) GTEST_SKIP() << path << " absent (the shared public networks)";
  const Network net = read_secomb(path.string(), ImportOptions{});
  Blood blood = rat_blood();
  blood.hematocrit = 0.4;
  blood.pries_max_diameter = 1;  // the law itself in every vessel (all are below 30 um)
  const auto start = std::chrono::steady_clock::now();
  const SteadyHematocritResult res = solve_steady_with_phase_separation(net, blood, 500, 1e-8, 0.5);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("mesentery with phase separation: %s after %d iterations, change %.2g, %.3f s\n",
              res.converged ? "converged" : "NOT converged", res.iterations, res.change, seconds);
  ASSERT_TRUE(res.converged);
  for (double h : res.hematocrit) {
    EXPECT_GE(h, 0.0);
    EXPECT_LT(h, 1.0);
  }
  // Red cells balance at every node, boundaries included (the file's hematocrits, else 0.4).
  std::vector<double> boundary_h(net.node_count(), 0.0);
  std::vector<char> has_boundary(net.node_count(), 0);
  for (const NodeBoundary& b : node_boundaries(net)) {
    has_boundary[b.node] = 1;
    boundary_h[b.node] = std::isnan(b.hematocrit) ? 0.4 : b.hematocrit;
  }
  double flux = 0;
  for (std::size_t v = 0; v < net.vessel_count(); ++v)
    flux = std::max(flux, std::abs(res.flow.flow[v]) * res.hematocrit[v]);
  for (std::size_t n = 0; n < net.node_count(); ++n)
    EXPECT_NEAR(red_cell_imbalance(net, res.flow.flow, res.hematocrit, static_cast<int>(n), boundary_h[n],
                                   has_boundary[n]),
                0.0, 1e-12 * flux)
        << "node " << net.node_id[n];
}
