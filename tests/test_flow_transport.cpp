// Red cells carried by the pulsatile solver's own fluxes (solver/flow_transport): with
// constant boundaries the transported hematocrits settle on the steady distribution of the
// run's flows (distribute_hematocrit, an independent node-by-node calculation) in 0D, 1D and
// hybrid networks with a loop; in pulsatile, reversing flow they stay in [0, 1), the cells
// follow the solver's volumes, and red cells are conserved; with the Pries viscosity fed
// back, stiff vessels under constant boundaries reach the steady solution of flows and
// hematocrits solved together (solve_steady_with_phase_separation).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "physics/phase_separation.hpp"
#include "physics/rheology.hpp"
#include "solver/flow_transport.hpp"
#include "pulse/pulse_solver.hpp"
#include "steady/steady_flow.hpp"
#include "steady/steady_hematocrit.hpp"
#include "tests/network_builders.hpp"

namespace hemotree {
namespace {

using namespace test_networks;
constexpr double pi = std::numbers::pi;

// The bridged diamond (tests/test_network_graphs_pulsatile.cpp), fed through vessel 0 from
// node 4 and drained through vessel 6 to node 5: vessels (from, to, length, diameter).
Network diamond(const std::array<double, 7>& diameter, double length_scale, double wave_speed) {
  const std::array<std::array<double, 3>, 7> list{{{4, 0, 1}, {0, 1, 4}, {0, 2, 1}, {1, 3, 1}, {3, 2, 2}, {1, 2, 1}, {2, 5, 1}}};
  Network net;
  for (int k = 0; k < 6; ++k) net.add_node(k);
  for (std::size_t v = 0; v < list.size(); ++v) {
    const double d = diameter[v];
    net.add_vessel(static_cast<std::int64_t>(v), static_cast<std::int32_t>(list[v][0]), static_cast<std::int32_t>(list[v][1]),
                   list[v][2] * length_scale, d, 0.1 * d, 1e6, 0);
    net.beta.push_back(beta_for_wave_speed(wave_speed, pi / 4 * d * d));
    net.reference_pressure.push_back(1333.0);
  }
  net.blood = newtonian(3.5e-3);
  net.blood->hematocrit = 0.45;
  return net;
}

// Runs the solver to t_end with the transport advanced every `every` steps, checking the
// hematocrits' bounds after each.
void run(PulseSolver& solver, FlowTransport& transport, double t_end, int every = 1) {
  while (solver.time() < t_end - 1e-12) {
    for (int k = 0; k < every; ++k) solver.step();
    transport.advance();
    for (const double h : transport.red_cells().discharge_hematocrit()) {
      EXPECT_GE(h, 0);
      EXPECT_LT(h, 1);
    }
  }
}

// Per vessel: the run's mean flows now (the solver's mode-0 means).
std::vector<double> flows(const PulseSolver& solver, const Network& net) {
  std::vector<double> q(net.vessel_count());
  for (std::size_t v = 0; v < q.size(); ++v) q[v] = solver.mean_flow(v);
  return q;
}

struct Case {
  const char* name;
  ModelChoice model;
  std::array<double, 7> diameter;
  double length_scale, wave_speed, flow, t_end;
};

TEST(FlowTransport, ConstantBoundariesSettleOnTheSteadyDistributionOfTheFlows) {
  // Microvessels (strong phase separation) as 0D vessels; 1 mm vessels (weak) in 1D and in a
  // hybrid. Each runs some 10 transit times of its blood.
  const Case cases[] = {
      {"0D microvessels", ModelChoice::zero_d, {20e-6, 12e-6, 15e-6, 9e-6, 8e-6, 6e-6, 20e-6}, 2e-4, 2.0, 2e-12, 20.0},
      {"1D", ModelChoice::one_d, {1e-3, 0.6e-3, 0.8e-3, 0.5e-3, 0.4e-3, 0.35e-3, 1e-3}, 1e-2, 5.0, 2e-7, 12.0},
      {"hybrid", ModelChoice::automatic, {1e-3, 0.6e-3, 0.8e-3, 0.5e-3, 0.4e-3, 0.35e-3, 1e-3}, 1e-2, 5.0, 2e-7, 12.0},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    Network net = diamond(c.diameter, c.length_scale, c.wave_speed);
    net.boundaries = {flow_boundary(4, c.flow), pressure_boundary(5, 1333.0)};
    SolverOptions options;
    options.model = c.model;
    options.degree = 2;
    PulseSolver solver(net, options);
    FlowTransportOptions t;
    t.viscosity_feedback = false;
    FlowTransport transport(net, solver, t);
    transport.begin_cycle();
    run(solver, transport, c.t_end);
    const RedCellCycle cycle = transport.close_cycle();
    // The last advance's faces: their hematocrits, against the node-by-node rule on the
    // run's own flows (mixing, the law at 1-in 2-out nodes, 0.45 at the inflow).
    const std::vector<double> expected =
        distribute_hematocrit(net, flows(solver, net), 0.45, net.blood->phase_separation_diameter_scale());
    const RedCellTransport& cells = transport.red_cells();
    const TransportGrid& grid = cells.grid();
    std::vector<double> got(net.vessel_count(), -1);
    for (std::size_t f = 0; f < grid.face_count(); ++f)
      if (grid.vessel[f] >= 0 && cells.blood_through()[f] != 0)
        got[static_cast<std::size_t>(grid.vessel[f])] = cells.cells_through()[f] / cells.blood_through()[f];
    double spread = 0;
    for (std::size_t v = 0; v < net.vessel_count(); ++v) {
      EXPECT_NEAR(got[v], expected[v], 1e-7) << "vessel " << v;
      spread = std::max(spread, std::abs(expected[v] - 0.45));
    }
    if (c.model == ModelChoice::zero_d) {
      EXPECT_GT(spread, 0.05);  // the law did separate
    }
    // Round-off over some 1e5 steps of sums (the red cells' own bookkeeping is exact).
    EXPECT_LT(std::abs(cycle.balance_error), 1e-11);
    // The cells hold the solver's volumes: the transport's from the vessels' tube laws, the
    // solver's 0D nodes' from their compliance coefficients, which are in float (6e-8 of
    // themselves): the two agree to that times the distended part of the volume (here 1.6e-12).
    const double held = [&] {
      double sum = 0;
      for (const double v : cells.volume()) sum += v;
      return sum;
    }();
    EXPECT_NEAR(held, solver.network_volume(), 1e-11 * held);
  }
}

TEST(FlowTransport, ReversingPulsatileFlowStaysBoundedAndConservesRedCells) {
  // An inflow that reverses for part of each 0.5 s cycle, into microvessels (0D), for 6 cycles.
  Network net = diamond({20e-6, 12e-6, 15e-6, 9e-6, 8e-6, 6e-6, 20e-6}, 2e-4, 2.0);
  const double period = 0.5;
  net.boundaries = {flow_boundary(4, tabulate([&](double t) { return 2e-12 * (0.4 + std::sin(2 * pi * t / period)); },
                                              period, 400, period)),
                    pressure_boundary(5, 1333.0)};
  SolverOptions options;
  options.model = ModelChoice::zero_d;
  PulseSolver solver(net, options);
  FlowTransport transport(net, solver);  // Newtonian blood: the feedback is a factor of 1
  double worst = 0;
  for (int cycle = 0; cycle < 6; ++cycle) {
    transport.begin_cycle();
    run(solver, transport, (cycle + 1) * period, 3);
    const RedCellCycle c = transport.close_cycle();
    worst = std::max(worst, std::abs(c.balance_error));
    for (std::size_t v = 0; v < net.vessel_count(); ++v) {
      EXPECT_GE(c.lowest[v], 0);
      EXPECT_LT(c.highest[v], 1);
      EXPECT_LE(c.lowest[v], c.highest[v]);
    }
  }
  EXPECT_LT(worst, 1e-12);
}

TEST(FlowTransport, ViscosityFeedbackReachesTheSteadyFlowsAndHematocritsSolvedTogether) {
  // Pries blood in stiff microvessels (distension 1e-5: the rigid steady solution is the
  // limit), constant boundaries: the pulsatile run's flows and hematocrits, each vessel's
  // viscosity at its own hematocrit step by step, against the steady iteration's.
  Network net = diamond({20e-6, 12e-6, 15e-6, 9e-6, 8e-6, 6e-6, 20e-6}, 2e-4, 200.0);
  Blood blood;
  blood.hematocrit = 0.45;
  net.blood = blood;
  net.boundaries = {flow_boundary(4, 2e-12), pressure_boundary(5, 1333.0)};
  SolverOptions options;
  options.model = ModelChoice::zero_d;
  PulseSolver solver(net, options);
  FlowTransport transport(net, solver);
  run(solver, transport, 6.0);
  const SteadyHematocritResult steady = solve_steady_with_phase_separation(net, blood, 1000, 1e-12, 0.5);
  ASSERT_TRUE(steady.converged);
  const RedCellTransport& cells = transport.red_cells();
  const TransportGrid& grid = cells.grid();
  double factor_spread = 0;
  for (const double f : solver.viscosity_factors()) factor_spread = std::max(factor_spread, std::abs(f - 1));
  EXPECT_GT(factor_spread, 0.02);  // the hematocrits moved the viscosities
  for (std::size_t f = 0; f < grid.face_count(); ++f) {
    const std::int32_t v = grid.vessel[f];
    if (v < 0) continue;
    const auto vi = static_cast<std::size_t>(v);
    EXPECT_NEAR(cells.cells_through()[f] / cells.blood_through()[f], steady.hematocrit[vi], 2e-4) << "vessel " << v;
    EXPECT_NEAR(solver.mean_flow(vi), steady.flow.flow[vi], 1e-3 * 2e-12) << "vessel " << v;
  }
}

}  // namespace
}  // namespace hemotree
