// The 1D-0D coupling of the pulse solver (--model auto): a vessel cut in two, its short half
// 0D, against the whole vessel 1D under a slow pulse; mass through every 1D-0D coupling to
// round-off; fifty cycles of a coupled network with many 1D substeps per 0D step without
// growth; and the choice of models.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "pulse/pulse_solver.hpp"
#include "pulse/step_cost.hpp"
#include "tests/network_builders.hpp"

using namespace hemotree;
using namespace hemotree::test_networks;

namespace {

constexpr double pi = std::numbers::pi;

// A Gaussian pulse of inflow (peak q at t0, width sigma) every period; t0 at least 5 sigma
// from both ends, so that the table wraps without a jump.
Waveform gaussian_pulse(double q, double t0, double sigma, double period) {
  return tabulate([&](double t) { return q * std::exp(-0.5 * std::pow((t - t0) / sigma, 2)); }, period, 2001, period);
}

// Vessels (from, to, length) of one diameter and wave speed, Newtonian blood, an outlet of
// the vessel's characteristic impedance at every terminal vessel (few reflections).
Network network(const std::vector<std::array<double, 3>>& vessels, int nodes, double diameter, double c) {
  Network net;
  for (int k = 0; k < nodes; ++k) net.add_node(k);
  const double area = pi / 4 * diameter * diameter, beta = beta_for_wave_speed(c, area);
  for (std::size_t v = 0; v < vessels.size(); ++v)
    net.add_vessel(static_cast<std::int64_t>(v), static_cast<std::int32_t>(vessels[v][0]),
                   static_cast<std::int32_t>(vessels[v][1]), vessels[v][2], diameter, 0.1 * diameter, 1e6, 0);
  net.beta.assign(vessels.size(), beta);
  net.reference_pressure.assign(vessels.size(), 1e4);
  net.blood = newtonian(3.5e-3);
  std::vector<int> leaving(static_cast<std::size_t>(nodes), 0);
  for (const auto& v : vessels) ++leaving[static_cast<std::size_t>(v[0])];
  for (std::size_t v = 0; v < vessels.size(); ++v)
    if (leaving[static_cast<std::size_t>(vessels[v][1])] == 0)
      net.outlets.push_back(resistance_outlet(static_cast<std::int32_t>(v), rho * c / area, 1e4));
  return net;
}

struct Samples {
  std::vector<double> t, p;
};

// Pressure at (vessel, x) after every step until t_end.
Samples record(PulseSolver& solver, std::size_t vessel, double x, double t_end) {
  Samples s;
  while (solver.time() < t_end) {
    solver.step();
    s.t.push_back(solver.time());
    s.p.push_back(solver.pressure_at(vessel, x));
  }
  return s;
}

double interpolate(const Samples& s, double t) {
  const auto k = static_cast<std::size_t>(std::lower_bound(s.t.begin(), s.t.end(), t) - s.t.begin());
  if (k == 0) return s.p.front();
  if (k >= s.t.size()) return s.p.back();
  const double w = (t - s.t[k - 1]) / (s.t[k] - s.t[k - 1]);
  return s.p[k - 1] + w * (s.p[k] - s.p[k - 1]);
}

// A 1D trunk splitting into two 0D vessels, one of which feeds a 1D vessel again (three
// coupled ends), pulsed once, and the options that make those two 0D.
Network three_couplings() {
  Network net = network({{0, 1, 0.15}, {1, 2, 0.01}, {1, 3, 0.012}, {3, 4, 0.2}}, 5, 4e-3, 6.0);
  net.inlet = Inlet{0, gaussian_pulse(8e-6, 0.4, 0.05, 0.8)};
  return net;
}
SolverOptions short_vessels_0d() {
  SolverOptions options;
  options.model = ModelChoice::automatic;
  options.lumped_transit = 0.01;
  return options;
}

// A 12 cm vessel and a 2 cm one in series (5 mm, c = 5 m/s), a pulse of width sigma at
// t = 0.5 s of a period of 1 s; the options of a run from rest, with the short one 0D or not
// (transits 0.024 s and 0.004 s).
Network split_vessel(double sigma) {
  Network net = network({{0, 1, 0.12}, {1, 2, 0.02}}, 3, 5e-3, 5.0);
  net.inlet = Inlet{0, gaussian_pulse(5e-6, 0.5, sigma, 1.0)};
  return net;
}
SolverOptions from_rest(bool short_half_0d) {
  SolverOptions options;
  options.start = StartChoice::rest;
  if (short_half_0d) {
    options.model = ModelChoice::automatic;
    options.lumped_transit = 0.01;
  }
  return options;
}

}  // namespace

// A 12 cm vessel and a 2 cm one in series (5 mm, c = 5 m/s) under a pulse of sigma = 0.1 s:
// the short one's transit (4 ms) is far below the pulse's time scale, kL = 2 pi f L / c = 0.13
// at 5 Hz. Made 0D, the pressures at the coupling and inside it follow the all-1D solution
// to well within (kL)^2 = 2 % of the pulse's amplitude (measured 0.1 %). Both start from rest,
// where the pulse starts too: the steady state of the mean flow is not the state of the
// pulse's first instant, and the two discretisations resolve that jump differently.
TEST(HybridModel, AShortHalfMade0dFollowsTheAll1dSolution) {
  const Network net = split_vessel(0.1);
  const SolverOptions one_d = from_rest(false), hybrid = from_rest(true);
  PulseSolver reference(net, one_d), coupled(net, hybrid);
  ASSERT_FALSE(reference.is_lumped(1));
  ASSERT_FALSE(coupled.is_lumped(0));
  ASSERT_TRUE(coupled.is_lumped(1));
  EXPECT_GT(coupled.substeps(), 1);
  for (const auto& [vessel, x] : {std::pair<std::size_t, double>{0, 1.0}, {1, 0.5}, {0, 0.5}}) {
    PulseSolver a(net, one_d), b(net, hybrid);
    const Samples exact = record(a, vessel, x, 0.8), hyb = record(b, vessel, x, 0.8);
    const auto [low, high] = std::minmax_element(exact.p.begin(), exact.p.end());
    double worst = 0;
    for (std::size_t k = 0; k < hyb.t.size(); ++k) worst = std::max(worst, std::abs(hyb.p[k] - interpolate(exact, hyb.t[k])));
    const double relative = worst / (*high - *low);
    std::printf("vessel %zu at x = %.1f: largest departure from all-1D %.3g of the pulse (%.1f Pa)\n", vessel, x,
                relative, *high - *low);
    EXPECT_LT(relative, 0.005);
  }
}

// Three coupled ends: the exchanged volumes against the stored one, every step, with one
// coupling pass and with three (the later passes start the 1D vessels again from the step's
// start: what they let through is still what the 0D vessels receive).
TEST(HybridModel, MassThroughEveryCouplingToRoundOff) {
  const Network net = three_couplings();
  for (const int passes : {1, 3}) {
    SolverOptions options = short_vessels_0d();
    options.coupling_passes = passes;
    PulseSolver solver(net, options);
    ASSERT_EQ(solver.lumped_count(), 2u);
    ASSERT_EQ(solver.coupling_passes(), passes);
    const double v0 = solver.network_volume();
    double worst = 0, in = 0;
    while (solver.time() < 0.8) {
      solver.step();
      const Eigen::Vector2d exchanged = solver.exchanged_volumes();
      in = exchanged(0);
      const double balance = in - exchanged(1) - (solver.network_volume() - v0);
      worst = std::max(worst, std::abs(balance));
    }
    std::printf("coupled mass, %d passes: largest |in - out - stored| %.3g m^3 against %.3g m^3 in\n", passes, worst,
                in);
    EXPECT_LT(worst, 1e-12 * in);
  }
}

// The coupling passes converge to the coupling's fixed point, where each 1D end's inflow held
// by the 0D prediction is the mean it lets through: a vessel whose short half is 0D, at the
// longest 0D step the passes are taken at by themselves (4e-3 of the period, 9 substeps).
// The departure of the coupling node's pressure from the fixed point (taken with 12 passes)
// falls by more than half with each pass (measured 0.31 to 0.37 a pass), and four passes
// keep the pulse's amplitude there within issue 5's 2 % of the all-1D solution (measured
// 1.1 %; one pass 0.2 %: at a single coupling the first pass's Robin response offsets the
// lag of the 0D step's mean inflow, which the fixed point keeps; across a network's
// couplings it does not, docs/solver.md §10).
TEST(HybridModel, CouplingPassesConvergeToTheFixedPoint) {
  const Network net = split_vessel(0.05);
  const SolverOptions one_d = from_rest(false);
  SolverOptions hybrid = from_rest(true);
  hybrid.lumped_step = 4e-3;
  auto pressures = [&](const SolverOptions& options) {
    PulseSolver solver(net, options);
    return record(solver, 0, 1.0, 0.8);
  };
  auto with_passes = [&](int passes) {
    SolverOptions options = hybrid;
    options.coupling_passes = passes;
    return pressures(options);
  };
  auto amplitude = [](const Samples& a) {
    const auto [low, high] = std::minmax_element(a.p.begin(), a.p.end());
    return *high - *low;
  };
  const double pulse = amplitude(pressures(one_d));
  const Samples fixed_point = with_passes(12);
  double last = 0;
  for (const int passes : {1, 2, 3, 4}) {
    const Samples s = with_passes(passes);
    double d = 0;
    for (std::size_t k = 0; k < s.t.size(); ++k) d = std::max(d, std::abs(s.p[k] - fixed_point.p[k]) / pulse);
    const double amplitude_error = std::abs(amplitude(s) - pulse) / pulse;
    std::printf("%d passes: departure from the fixed point %.3g, amplitude against all-1D %.3g of the pulse\n", passes, d,
                amplitude_error);
    if (passes > 1) {
      EXPECT_LT(d, 0.5 * last);
    }
    if (passes == 4) {
      EXPECT_LT(amplitude_error, 0.02);
    }
    last = d;
  }
}

// The passes a run takes by itself: as many as lower the cost of a cycle, N C_1D + C_0D / N.
TEST(HybridModel, CouplingPassesThatCostLeast) {
  using step_cost::cheapest_coupling_passes;
  EXPECT_EQ(cheapest_coupling_passes(1.0, 1.0, 4), 1);    // 2 passes: 2 + 0.5 > 1 + 1
  EXPECT_EQ(cheapest_coupling_passes(1.0, 2.5, 4), 2);    // 2 + 1.25 < 1 + 2.5
  EXPECT_EQ(cheapest_coupling_passes(10.0, 118.0, 4), 3); // the full tree: 30 + 39 against 20 + 59 and 40 + 29.5
  EXPECT_EQ(cheapest_coupling_passes(0.0, 1.0, 4), 4);    // no 1D work: the most allowed
  EXPECT_EQ(cheapest_coupling_passes(1.0, 1e6, 1), 1);
}

// After the run the report needs the vessels' models only: the 0D vessels' arrays are freed,
// the count of 0D vessels and every vessel's model stay, and the solver refuses another step
// (it would step the 1D vessels alone).
TEST(HybridModel, TheZeroDStateReleasedForTheReport) {
  const Network net = three_couplings();
  PulseSolver solver(net, short_vessels_0d());
  solver.step();
  std::vector<bool> lumped(net.vessel_count());
  for (std::size_t v = 0; v < lumped.size(); ++v) lumped[v] = solver.is_lumped(v);
  solver.release_lumped_state();
  EXPECT_EQ(solver.lumped_count(), 2u);
  EXPECT_TRUE(solver.lumped().empty());
  for (std::size_t v = 0; v < lumped.size(); ++v) EXPECT_EQ(solver.is_lumped(v), lumped[v]);
  EXPECT_THROW(solver.step(), std::logic_error);
}

// Fifty cycles of a coupled tree with 24 1D substeps per 0D step: the last cycle's pressures
// repeat the tenth's (periodic, nothing grows; measured 1e-10 Pa from cycle to cycle), with
// one coupling pass and with the four the step would take by itself.
TEST(HybridModel, FiftyCyclesWithoutGrowth) {
  for (const int passes : {1, 4}) {
    Network net = network({{0, 1, 0.1}, {1, 2, 0.004}, {1, 3, 0.005}, {2, 4, 0.08}, {2, 5, 0.003}, {3, 6, 0.002}},
                          7, 3e-3, 6.0);
    const double period = 0.2;
    net.inlet = Inlet{0, gaussian_pulse(4e-6, 0.1, 0.02, period)};
    SolverOptions options;
    options.model = ModelChoice::automatic;
    options.lumped_transit = 0.01;  // 0.002 s: the 2 to 5 mm vessels are 0D
    options.lumped_step = 0.02;
    options.coupling_passes = passes;
    PulseSolver solver(net, options);
    ASSERT_EQ(solver.lumped_count(), 4u);
    const auto steps = static_cast<std::size_t>(std::ceil(period / solver.dt() - 1e-9));
    solver.set_time_step(period / static_cast<double>(steps));
    std::printf("50 cycles: %zu steps of %.3g s per cycle, %d 1D substeps each\n", steps, solver.dt(), solver.substeps());
    EXPECT_GE(solver.substeps(), 20);
    std::vector<double> tenth, last;
    for (int cycle = 1; cycle <= 50; ++cycle) {
      std::vector<double> p;
      for (std::size_t k = 0; k < steps; ++k) {
        solver.step();
        p.push_back(solver.pressure_at(3, 0.5));
      }
      if (cycle == 10) tenth = p;
      if (cycle == 50) last = p;
    }
    const auto [low, high] = std::minmax_element(last.begin(), last.end());
    double change = 0;
    for (std::size_t k = 0; k < steps; ++k) change = std::max(change, std::abs(last[k] - tenth[k]));
    std::printf("50 cycles, %d passes: pulse %.2f Pa; largest change from cycle 10 to cycle 50 %.3g Pa\n", passes, *high - *low, change);
    EXPECT_LT(change, 1e-9 * (*high - *low));
    EXPECT_GT(*high - *low, 10.0);
  }
}

TEST(HybridModel, ModelsAreChosenByTransitTime) {
  Network net = network({{0, 1, 0.1}, {1, 2, 0.001}}, 3, 3e-3, 5.0);
  net.inlet = Inlet{0, gaussian_pulse(4e-6, 0.5, 0.05, 1.0)};
  SolverOptions options;
  options.model = ModelChoice::automatic;
  options.lumped_transit = 1e-3;  // transits 0.02 s and 2e-4 s
  const PulseSolver automatic(net, options);
  EXPECT_FALSE(automatic.is_lumped(0));
  EXPECT_TRUE(automatic.is_lumped(1));
  EXPECT_EQ(automatic.degree(1), -1);
  options.model = ModelChoice::zero_d;
  const PulseSolver all_0d(net, options);
  EXPECT_EQ(all_0d.lumped_count(), 2u);
  EXPECT_EQ(all_0d.element_count(), 0u);
  // A reflection outlet keeps its vessel 1D under auto, and is refused under 0d.
  net.outlets[0] = reflection_outlet(1, 0.0);
  options.model = ModelChoice::automatic;
  EXPECT_FALSE(PulseSolver(net, options).is_lumped(1));
  options.model = ModelChoice::zero_d;
  EXPECT_THROW(PulseSolver(net, options), InputError);
}

// A start from another solver of the same network and models at another degree (the
// settling cycle at a low degree, solver/settling_cycle.hpp): the 1D vessels' areas and
// flows, polynomials of degree 2 there, are projected onto degree 5 exactly (to round-off),
// the 0D vessels' state is taken as it is, and the clock starts again; a solver of another
// network, or of other models, is refused.
TEST(HybridModel, AStartFromAnotherDegreeTakesItsState) {
  const Network net = three_couplings();
  SolverOptions coarse_options = short_vessels_0d(), fine_options = short_vessels_0d();
  coarse_options.degree = 2;
  fine_options.degree = 5;
  PulseSolver coarse(net, coarse_options), fine(net, fine_options);
  ASSERT_EQ(coarse.lumped_count(), 2u);
  for (int k = 0; k < 150; ++k) coarse.step();  // away from any start the fine one knows
  fine.start_from(coarse);
  EXPECT_EQ(fine.time(), 0.0);
  for (std::size_t v = 0; v < net.vessel_count(); ++v)
    for (const double x : {0.0, 0.3, 0.5, 0.8, 1.0}) {
      const double p = coarse.pressure_at(v, x), q = coarse.flow_at(v, x);
      EXPECT_NEAR(fine.pressure_at(v, x), p, 1e-10 * std::abs(p)) << v << " " << x;
      EXPECT_NEAR(fine.flow_at(v, x), q, 1e-10 * std::abs(q) + 1e-18) << v << " " << x;
    }
  fine.step();  // and it goes on from there
  EXPECT_GT(fine.time(), 0.0);

  const Network other = split_vessel(0.1);
  PulseSolver elsewhere(other, short_vessels_0d());
  EXPECT_THROW(fine.start_from(elsewhere), std::invalid_argument);
  SolverOptions all_1d = fine_options;
  all_1d.model = ModelChoice::one_d;
  PulseSolver other_models(net, all_1d);
  EXPECT_THROW(fine.start_from(other_models), std::invalid_argument);
}
