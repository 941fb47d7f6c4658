// The pulsatile run on measured networks: loops, several inlets and outlets, boundary
// conditions at nodes where one vessel ends, at either end of it. Constant boundaries give
// the steady (Kirchhoff) solution in every model; a network written with its boundary
// vessels reversed gives the mirror image; several pulsatile inflows balance over a cycle;
// the refusals; and the rat mesentery where the shared data is present.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli/setting_words.hpp"
#include "core/errors.hpp"
#include "core/setting_error.hpp"
#include "exchange/foreign_format.hpp"
#include "exchange/secomb.hpp"
#include "solver/cycle_statistics.hpp"
#include "pulse/pulse_solver.hpp"
#include "steady/steady_flow.hpp"
#include "tests/network_builders.hpp"
#include "tests/shared_networks.hpp"

using namespace hemotree;
using namespace hemotree::test_networks;

namespace {

constexpr double pi = std::numbers::pi;

void sort_boundaries(Network& net) {
  std::sort(net.boundaries.begin(), net.boundaries.end(),
            [](const NodeBoundary& a, const NodeBoundary& b) { return a.node < b.node; });
}

// Vessels (from, to, length) of 1 mm, wave speed 5 m/s at rest, reference pressure p_ref,
// Newtonian blood.
Network vessels(const std::vector<std::array<double, 3>>& list, int nodes, double p_ref) {
  Network net;
  for (int k = 0; k < nodes; ++k) net.add_node(k);
  const double d = 1e-3, area = pi / 4 * d * d;
  for (std::size_t v = 0; v < list.size(); ++v)
    net.add_vessel(static_cast<std::int64_t>(v), static_cast<std::int32_t>(list[v][0]),
                   static_cast<std::int32_t>(list[v][1]), list[v][2], d, 1e-4, 1e6, 0);
  net.beta.assign(list.size(), beta_for_wave_speed(5.0, area));
  net.reference_pressure.assign(list.size(), p_ref);
  net.blood = newtonian(3.5e-3);
  return net;
}

// The bridged diamond of tests/test_steady_flow.cpp (vessels 1: 0->1, 2: 0->2, 3: 1->3,
// 4: 3->2 written against its flow, 5: 1->2 the bridge), fed through vessel 0 from node 4
// and drained through vessel 6 to node 5, where the boundaries sit (a boundary needs a node
// where one vessel ends). reversed: vessels 0 and 6 written the other way (0 -> 4, 5 -> 3):
// the inflow at a vessel's `to` end, the drain's condition at a `from` end. Vessels 1 (4 cm)
// and 4 (2 cm) hold a wave (1D under --model auto), the others are short (0D).
Network looped(bool reversed, double p_ref) {
  const double feed_from = reversed ? 0 : 4, feed_to = reversed ? 4 : 0;
  const double drain_from = reversed ? 5 : 3, drain_to = reversed ? 3 : 5;
  return vessels({{feed_from, feed_to, 0.01},
                  {0, 1, 0.04},
                  {0, 2, 0.01},
                  {1, 3, 0.01},
                  {3, 2, 0.02},
                  {1, 2, 0.01},
                  {drain_from, drain_to, 0.01}},
                 6, p_ref);
}

SolverOptions options_for(ModelChoice model) {
  SolverOptions o;
  o.model = model;
  o.degree = 2;
  return o;
}

const char* name(ModelChoice m) {
  return m == ModelChoice::one_d ? "1d" : m == ModelChoice::zero_d ? "0d" : "auto";
}

void run_until(PulseSolver& solver, double t_end) {
  while (solver.time() < t_end - 1e-12) solver.step();
}

// The pressure at a node, read at the end of vessel v there.
double node_pressure(const PulseSolver& s, const Network& net, std::size_t v, std::int32_t node) {
  return s.pressure_at(v, net.to[v] == node ? 1.0 : 0.0);
}

}  // namespace

// Constant boundaries, a start at rest: the run settles on the steady solution of the
// network's Poiseuille resistances (solve_steady_flow), in every model and with the boundary
// vessels either way round. Tolerance 2e-3 of the network's pressure drop (and of the
// inflow for flows): with Q = 1e-9 m^3/s the drop is about 6 Pa, which distends the lumens
// by 2 dp / (beta sqrt(A)) = 2e-4 and lowers the resistances by four times that, and the
// junctions' total pressure adds rho u^2 / 2 = 1e-3 Pa (2e-4 of the drop); the rigid
// steady solution has neither.
TEST(NetworkGraphsPulsatile, ConstantBoundariesSettleOnTheSteadySolution) {
  const double q = 1e-9, p_out = 1333.0;
  for (const bool reversed : {false, true})
    for (const ModelChoice model : {ModelChoice::one_d, ModelChoice::zero_d, ModelChoice::automatic}) {
      Network net = looped(reversed, p_out);
      net.boundaries = {flow_boundary(4, Waveform::constant_value(q)), pressure_boundary(5, p_out)};
      sort_boundaries(net);
      const SteadyFlow steady = solve_steady_flow(net, vessel_resistances(net, *net.blood), 0.0);
      SolverOptions options = options_for(model);
      options.start = StartChoice::rest;
      PulseSolver solver(net, options);
      if (model == ModelChoice::automatic) {
        EXPECT_FALSE(solver.is_lumped(1));  // a hybrid: the long vessels 1D, the others 0D
        EXPECT_FALSE(solver.is_lumped(4));
        EXPECT_TRUE(solver.is_lumped(2));
      }
      run_until(solver, 2.0);
      const double drop = steady.node_pressure[4] - p_out;
      ASSERT_GT(drop, 1.0);
      double q_error = 0, p_error = 0;
      for (std::size_t v = 0; v < net.vessel_count(); ++v) {
        SCOPED_TRACE(std::string("--model ") + name(model) + (reversed ? ", reversed" : "") + ", vessel " +
                     std::to_string(v));
        EXPECT_NEAR(solver.mean_flow(v), steady.flow[v], 2e-3 * q);
        q_error = std::max(q_error, std::abs(solver.mean_flow(v) - steady.flow[v]) / q);
        for (const std::int32_t node : {net.from[v], net.to[v]}) {
          const double p = node_pressure(solver, net, v, node), expected = steady.node_pressure[static_cast<std::size_t>(node)];
          EXPECT_NEAR(p, expected, 2e-3 * drop);
          p_error = std::max(p_error, std::abs(p - expected) / drop);
        }
      }
      std::printf("[ steady ] --model %s%s (%zu 0D): flows within %.2g of the inflow, pressures within %.2g of the "
                  "drop (%.3g Pa)\n",
                  name(model), reversed ? ", reversed" : "", solver.lumped_count(), q_error, p_error, drop);
      // What enters leaves: the boundary volumes of the run's last state.
      const RunBoundaries& list = solver.boundary_list();
      ASSERT_EQ(list.size(), 2u);
      EXPECT_EQ(solver.boundary_entering()[0], 1);  // the flow in (node 4)
      EXPECT_EQ(solver.boundary_entering()[1], 0);  // the pressure node lets it out
    }
}

// A half-sine inflow and an RCR outlet, with the inflow at a vessel's `to` end and the
// outlet at a `from` end: the same solution as the usual orientation, flows negated in the
// reversed vessels. The schemes are symmetric under x -> -x, Q -> -Q, so the difference is
// rounding (1e-9 of the pulse's scales allows for its growth over 2 000 steps).
TEST(NetworkGraphsPulsatile, ReversedBoundaryVesselsGiveTheMirrorImage) {
  Waveform pulse;
  pulse.shape = Waveform::Shape::half_sine;
  pulse.period = 0.5;
  pulse.mean = 2e-9;
  pulse.systole = 0.15;
  for (const ModelChoice model : {ModelChoice::one_d, ModelChoice::zero_d, ModelChoice::automatic}) {
    std::vector<Network> nets;
    for (const bool reversed : {false, true}) {
      Network net = looped(reversed, 1333.0);
      net.boundaries = {flow_boundary(4, pulse), outlet_boundary(5, rcr_outlet(-1, 2e9, 2e-13, 8e9, 1333.0))};
      sort_boundaries(net);
      nets.push_back(net);
    }
    // From the steady start: the periodic one's sparse LU orders the mirrored network's nodes
    // otherwise, which leaves the two starts a rounding apart, and the steps a bit apart.
    SolverOptions options = options_for(model);
    options.start = StartChoice::steady;
    PulseSolver usual(nets[0], options), mirrored(nets[1], options);
    ASSERT_EQ(usual.dt(), mirrored.dt());
    double p_scale = 0, q_scale = pulse.peak(), p_diff = 0, q_diff = 0;
    while (usual.time() < pulse.period - 1e-12) {
      usual.step();
      mirrored.step();
      for (std::size_t v = 0; v < nets[0].vessel_count(); ++v) {
        const bool flipped = v == 0 || v == 6;
        for (const double x : {0.0, 0.5, 1.0}) {
          const double y = flipped ? 1 - x : x, sign = flipped ? -1.0 : 1.0;
          p_scale = std::max(p_scale, std::abs(usual.pressure_at(v, x) - 1333.0));
          p_diff = std::max(p_diff, std::abs(usual.pressure_at(v, x) - mirrored.pressure_at(v, y)));
          q_diff = std::max(q_diff, std::abs(usual.flow_at(v, x) - sign * mirrored.flow_at(v, y)));
        }
      }
    }
    SCOPED_TRACE(std::string("--model ") + name(model));
    std::printf("[ mirror ] --model %s: pressures within %.2g of the pulse's %.3g Pa, flows within %.2g of its peak\n",
                name(model), p_diff / p_scale, p_scale, q_diff / q_scale);
    EXPECT_GT(p_scale, 1.0);
    EXPECT_LE(p_diff, 1e-9 * p_scale);
    EXPECT_LE(q_diff, 1e-9 * q_scale);
    // The outlet's volume, out through a `from` end, is the same.
    EXPECT_NEAR(usual.exchanged_volumes()(1), mirrored.exchanged_volumes()(1), 1e-9 * usual.exchanged_volumes()(1));
  }
}

// Two pulsatile inflows (tables of one period), a prescribed outflow, a pressure and an R
// outlet on a network with two loops: over a cycle the scheme conserves mass to round-off,
// each prescribed flow's volume is its waveform's, and once periodic (compliance balance
// every cycle) what enters leaves.
TEST(NetworkGraphsPulsatile, SeveralPulsatileInflowsBalanceOverAPeriodicCycle) {
  const double period = 0.8;
  // A ladder of two rails (0-1-2, 3-4-5) and three rungs, lead vessels to the boundary nodes 6..10.
  Network net = vessels({{0, 1, 0.02},
                         {1, 2, 0.01},
                         {3, 4, 0.01},
                         {4, 5, 0.03},
                         {0, 3, 0.01},
                         {1, 4, 0.01},
                         {5, 2, 0.01},
                         {6, 0, 0.01},    // inflow A
                         {3, 7, 0.01},    // inflow B, at its lead vessel's `to` end
                         {2, 8, 0.01},    // the pressure
                         {9, 5, 0.01},    // the prescribed outflow, at a `from` end
                         {4, 10, 0.01}},  // the R outlet
                        11, 1333.0);
  auto table = [&](double mean, double phase) {
    return tabulate([&](double t) { return mean * (1 + 0.6 * std::sin(2 * pi * (t / period - phase))); }, period, 81,
                    period);
  };
  const Waveform a = table(3e-9, 0.0), b = table(1e-9, 0.3);
  net.boundaries = {flow_boundary(6, a), flow_boundary(7, b), pressure_boundary(8, 1333.0),
                    flow_boundary(9, Waveform::constant_value(-0.5e-9)),
                    outlet_boundary(10, resistance_outlet(-1, 2e9, 1333.0))};
  sort_boundaries(net);
  for (const ModelChoice model : {ModelChoice::one_d, ModelChoice::automatic}) {
    SCOPED_TRACE(std::string("--model ") + name(model));
    PulseSolver solver(net, options_for(model));
    EXPECT_DOUBLE_EQ(solver.period(), period);
    const auto steps = static_cast<std::size_t>(std::ceil(period / solver.dt() - 1e-9));
    solver.set_time_step(period / static_cast<double>(steps));
    CycleStatistics stats(net, solver, 1 / period);
    solver.balance_compliances(period);
    CycleSummary last;
    for (int cycle = 0; cycle < 6; ++cycle) {
      stats.begin(solver);
      for (std::size_t k = 0; k < steps; ++k) {
        solver.step();
        stats.sample(solver, solver.time(), solver.dt());
      }
      last = stats.close(solver);
      solver.balance_compliances(period);
    }
    std::printf("[ inflows ] --model %s: mass balance %.2g, in %.4g, out %.4g m^3/s, volume change %.3g m^3\n",
                name(model), last.conservation_error, last.inlet_mean_flow, last.outlets_mean_flow, last.volume_change);
    EXPECT_LT(std::abs(last.conservation_error), 1e-10);
    const RunBoundaries& list = solver.boundary_list();
    ASSERT_EQ(last.boundary_mean_flow.size(), list.size());
    double in = 0, net_in = 0;
    for (std::size_t i = 0; i < list.size(); ++i) {
      net_in += last.boundary_mean_flow[i];
      in += std::max(last.boundary_mean_flow[i], 0.0);
      if (list.type(i) != BoundaryType::flow) continue;
      // The scheme's quadrature of the table over 1 000+ steps: 1e-4.
      EXPECT_NEAR(last.boundary_mean_flow[i], list.waveform(i).mean_value(), 1e-4 * 3e-9) << "boundary " << i;
    }
    EXPECT_NEAR(last.inlet_mean_flow, in, 1e-6 * in);  // the flows and the pressure node (it lets blood in)
    EXPECT_NEAR(net_in, 0.0, 1e-4 * in);               // periodic: nothing stored over the cycle
    EXPECT_NEAR(last.inlet_mean_flow, last.outlets_mean_flow, 1e-4 * in);
  }
}

TEST(NetworkGraphsPulsatile, RefusesWhatItCannotRun) {
  auto message = [](const Network& net, ModelChoice model = ModelChoice::one_d) {
    try {
      PulseSolver solver(net, options_for(model));
    } catch (const SettingError& e) {  // as hemosolve shows it
      return e.in_words(hemosolve_words());
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  {
    // The bridged diamond without its lead vessels: the boundaries sit where two vessels meet.
    Network net = vessels({{0, 1, 0.01}, {0, 2, 0.01}, {1, 3, 0.01}, {3, 2, 0.01}, {1, 2, 0.01}}, 4, 1333.0);
    net.boundaries = {flow_boundary(0, Waveform::constant_value(1e-9)), pressure_boundary(3, 1333.0)};
    EXPECT_EQ(message(net), "hemosolve's pulsatile run takes boundary conditions where one vessel ends; node 0 joins 2 "
                            "vessels; --steady takes any");
    EXPECT_EQ(message(net, ModelChoice::zero_d), message(net));
  }
  {
    // Two pulsatile boundaries of different periods.
    Network net = looped(false, 1333.0);
    Waveform fast;
    fast.period = 0.8;
    fast.mean = 1e-9;
    Waveform slow = fast;
    slow.period = 1.0;
    net.boundaries = {flow_boundary(4, fast), flow_boundary(5, slow)};
    const std::string m = message(net);
    EXPECT_NE(m.find("different periods"), std::string::npos) << m;
    EXPECT_NE(m.find("node 4"), std::string::npos) << m;
  }
  {
    // A free end without a condition, named by its node.
    Network net = looped(false, 1333.0);
    net.boundaries = {flow_boundary(4, Waveform::constant_value(1e-9))};
    const std::string m = message(net);
    EXPECT_NE(m.find("node 5"), std::string::npos) << m;
    EXPECT_NE(m.find("no boundary condition"), std::string::npos) << m;
  }
  {
    // A reflection outlet on a 0D vessel.
    Network net = looped(false, 1333.0);
    NodeBoundary reflect;
    reflect.node = 5;
    reflect.type = BoundaryType::reflection;
    reflect.outlet = reflection_outlet(-1, 0.0);
    net.boundaries = {flow_boundary(4, Waveform::constant_value(1e-9)), reflect};
    const std::string m = message(net, ModelChoice::zero_d);
    EXPECT_NE(m.find("reflection outlet needs a 1D vessel"), std::string::npos) << m;
    EXPECT_EQ(message(net, ModelChoice::one_d), "");
  }
}

// The rat mesentery (Secomb's network.dat: 1130 vessels, 159 loops, 31 inflows, 4
// prescribed outflows and a pressure): the run (auto: every vessel 0D) stays on the steady
// state of its own compliant vessels, and against the rigid steady solution (--steady's)
// the distension shows; the numbers are printed for the record.
TEST(NetworkGraphsPulsatile, RatMesenteryRunsAndMatchesItsSteadyState) {
  const std::string file = shared_mesentery().string();
  if (!std::filesystem::exists(file)) GTEST_SKIP() << file << " is absent";
  Network net = read_secomb(file, ImportOptions{});
  fill_missing_walls(net, ImportOptions{});
  Blood blood = net.blood.value_or(Blood{});
  blood.mean_cell_volume = 55e-18;
  blood.plasma_viscosity = 1.0466e-3;
  blood.hematocrit = 0.4;
  net.blood = blood;
  SolverOptions options;
  options.model = ModelChoice::automatic;
  PulseSolver solver(net, options);
  ASSERT_TRUE(solver.started_from_steady());
  const double period = solver.period();
  EXPECT_EQ(period, 1.0);  // constant boundaries
  const auto steps = static_cast<std::size_t>(std::ceil(period / solver.dt() - 1e-9));
  solver.set_time_step(period / static_cast<double>(steps));
  CycleStatistics stats(net, solver, 1.0);
  stats.begin(solver);
  const auto started = std::chrono::steady_clock::now();
  for (std::size_t k = 0; k < steps; ++k) {
    solver.step();
    stats.sample(solver, solver.time(), solver.dt());
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  const CycleSummary cycle = stats.close(solver);
  EXPECT_LT(std::abs(cycle.conservation_error), 1e-9);
  // Against the distended steady state (the run's start): the run holds it.
  const ViscosityTable viscosity(blood);
  std::vector<TubeLaw> laws;
  for (std::size_t v = 0; v < net.vessel_count(); ++v) laws.push_back(solver.law(v));
  const SteadyFlow distended = solve_distended_steady_flow(net, blood, laws, viscosity, 0.0);
  const SteadyFlow rigid = solve_steady_flow(net, vessel_resistances(net, blood), 0.0);
  std::vector<double> to_distended, to_rigid;
  double total = 0;
  for (std::size_t v = 0; v < net.vessel_count(); ++v) total = std::max(total, std::abs(distended.flow[v]));
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    const double q = cycle.vessels[v].mean_flow;
    to_distended.push_back(std::abs(q - distended.flow[v]) / total);
    if (rigid.flow[v] != 0) to_rigid.push_back(std::abs(q - rigid.flow[v]) / std::abs(rigid.flow[v]));
  }
  EXPECT_LT(*std::max_element(to_distended.begin(), to_distended.end()), 1e-3);
  std::sort(to_rigid.begin(), to_rigid.end());
  std::printf("[ mesentery ] %zu 0D vessels; one cycle in %.3f s (%zu steps); mean flows against the rigid steady "
              "solution: median %.3g, largest %.3g relative; against the distended steady state at most %.3g of the "
              "largest flow\n",
              solver.lumped_count(), wall, steps, to_rigid[to_rigid.size() / 2], to_rigid.back(),
              *std::max_element(to_distended.begin(), to_distended.end()));
  EXPECT_LT(wall, 30.0);
}
