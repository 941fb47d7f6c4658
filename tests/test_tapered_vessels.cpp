// Tapered vessels (Network::distal_diameter) in the 1D and 0D models.
//
// The 1D model of a tapered vessel carries the taper's source terms in its momentum equation
// (physics/vessel_taper.hpp, docs/solver.md §1a). Checks, each against an independent
// calculation:
// (a) the rest state (Q = 0, A = pi D(x)^2 / 4, one pressure all along) stays at rest to
//     round-off, in a lone vessel and across a junction, for a given beta, thin and thick walls;
// (b) steady flow through a tapered vessel into a resistance: the inlet pressure of the steady
//     1D model (its ODE integrated by RK4), and in a stiff tube the closed-form tapered
//     Poiseuille resistance plus the convective (Bernoulli) term;
// (c) a pulse crossing a short taper: transmitted as 2 Y0 / (Y0 + Y1) of linear theory;
// (d) the closed forms of physics/ (resistance, inertance, thin-wall compliance) and the 0D
//     tapered vessel's R, L, C against composite Simpson quadrature along the vessel;
// (e) a tapered vessel cut into N uniform pieces: its steady inlet pressure approaches the
//     tapered vessel's as 1 / N^2.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "physics/poiseuille.hpp"
#include "physics/rheology.hpp"
#include "physics/wall_law.hpp"
#include "pulse/legendre_basis.hpp"
#include "pulse/lumped_vessels.hpp"
#include "solver/probes.hpp"
#include "pulse/pulse_solver.hpp"
#include "physics/vessel_taper.hpp"
#include "tests/network_builders.hpp"

using namespace hemotree;
using namespace hemotree::test_networks;

namespace {

constexpr double pi = std::numbers::pi;

// Composite Simpson rule of f on [0, length] with n (even) intervals.
double simpson(const std::function<double(double)>& f, double length, int n = 20000) {
  const double h = length / n;
  double sum = f(0) + f(length);
  for (int i = 1; i < n; ++i) sum += (i % 2 ? 4 : 2) * f(i * h);
  return sum * h / 3;
}

// A single vessel with a given beta (at d0), tapering from d0 to d1.
Network tapered_vessel(double length, double d0, double d1, double beta0, double reference_pressure,
                       const Blood& blood) {
  Network net = chain(1, length, d0, beta0, reference_pressure, blood);
  net.distal_diameter = {d1};
  return net;
}

Waveform constant_flow(double q, double period = 1000.0) {
  Waveform w;
  w.shape = Waveform::Shape::table;
  w.period = period;
  w.time = {0.0, 0.01, period - 1};
  w.value = {0.0, q, q};
  return w;
}

// The largest departure from rest over all vessels, at 41 points of each: |A - A_rest| / A_rest
// and |Q| / (A_rest c0), c0 the wave speed there.
struct RestDeparture {
  double area = 0, flow = 0;
};
RestDeparture rest_departure(const PulseSolver& s, const Network& net) {
  RestDeparture d;
  for (std::size_t v = 0; v < net.vessel_count(); ++v)
    for (int i = 0; i <= 40; ++i) {
      const double x = i / 40.0, diameter = net.diameter[v] + (net.diameter_at_to(v) - net.diameter[v]) * x;
      const double rest = pi / 4 * diameter * diameter;
      const double c0 = s.law_at(v, x).wave_speed(rest);
      d.area = std::max(d.area, std::abs(s.area_at(v, x) - rest) / rest);
      d.flow = std::max(d.flow, std::abs(s.flow_at(v, x)) / (rest * c0));
    }
  return d;
}

}  // namespace

// ---- (a) the rest state ------------------------------------------------------------------

// A vessel narrowing to half its diameter, at rest with no inflow and a non-reflecting end:
// every coefficient must stay where it is, to round-off, for 2000 steps.
TEST(TaperedVessels, RestStateStaysAtRestWithAGivenBeta) {
  const double d0 = 4e-3, d1 = 2e-3, length = 0.1;
  const double beta0 = beta_for_wave_speed(5.0, pi / 4 * d0 * d0);
  for (const int degree : {2, 3, 7})
    for (const int elements : {1, 4}) {
      Network net = tapered_vessel(length, d0, d1, beta0, 1333.0, newtonian(3.5e-3));
      net.inlet = Inlet{0, constant_flow(0.0)};
      net.outlets.push_back(reflection_outlet(0, 0.0));
      SolverOptions o;
      o.degree = degree;
      o.elements = elements;
      o.start = StartChoice::rest;
      PulseSolver s(net, o);
      for (int k = 0; k < 2000; ++k) s.step();
      const RestDeparture d = rest_departure(s, net);
      std::printf("[ rest ] given beta, degree %d, %d elements: |dA|/A %.2e, |Q|/(A c0) %.2e\n", degree, elements, d.area,
                  d.flow);
      EXPECT_LT(d.area, 1e-13);
      EXPECT_LT(d.flow, 1e-13);
    }
}

// The walls: a thin-walled and a thick-walled tapered vessel (E, h constant along it) feed a
// junction with a tapered and a uniform thin-walled daughter. All rest at p_ext: their
// measured lumens are at zero transmural pressure. The degree-1 rule is overridden: tapered
// vessels take at least degree 2.
TEST(TaperedVessels, RestStateStaysAtRestThroughAJunctionWithWallLaws) {
  for (const double parent_wall : {0.08, 0.3}) {  // h / D: thin, then thick
    Network net;
    for (int k = 0; k < 4; ++k) net.add_node(k);
    const double d0 = 2e-3, d1 = 1.2e-3;
    net.add_vessel(0, 0, 1, 0.05, d0, parent_wall * d0, 0.8e6, 0);
    net.add_vessel(1, 1, 2, 0.03, 1.0e-3, 0.1e-3, 0.8e6, 1);
    net.add_vessel(2, 1, 3, 0.04, 0.9e-3, 0.09e-3, 0.8e6, 1);
    net.distal_diameter = {d1, 0.6e-3, std::numeric_limits<double>::quiet_NaN()};
    net.blood = newtonian(3.5e-3);
    net.inlet = Inlet{0, constant_flow(0.0)};
    net.outlets.push_back(reflection_outlet(1, 0.3));
    net.outlets.push_back(resistance_outlet(2, 1e10, 10 * 133.322));
    SolverOptions o;
    o.degree = 1;
    o.elements = 2;
    o.start = StartChoice::rest;
    PulseSolver s(net, o);
    EXPECT_EQ(s.degree(0), 2);
    EXPECT_EQ(s.degree(1), 2);
    EXPECT_EQ(s.degree(2), 1);
    for (int k = 0; k < 2000; ++k) s.step();
    const RestDeparture d = rest_departure(s, net);
    std::printf("[ rest ] junction, parent h/D %.2f: |dA|/A %.2e, |Q|/(A c0) %.2e, p at the inlet %.9f Pa\n", parent_wall,
                d.area, d.flow, s.pressure_at(0, 0.0));
    EXPECT_LT(d.area, 1e-13);
    EXPECT_LT(d.flow, 1e-13);
    for (std::size_t v = 0; v < 3; ++v)
      for (const double x : {0.0, 0.5, 1.0}) EXPECT_NEAR(s.pressure_at(v, x), 10 * 133.322, 1e-9);
    // A probe reads the pressure with the law where it sits: at rest, p_ext all along the taper
    // (the proximal law at the narrower lumen downstream would read far below it).
    ProbeRecorder probes({Probe{0, 0, 0.5}, Probe{0, 0, 1.0}});
    probes.sample(s);
    std::istringstream row(probes.rows());
    std::string t, p_mid, q_mid, a_mid, u_mid, p_end;
    std::getline(row, t, ',');
    std::getline(row, p_mid, ',');
    std::getline(row, q_mid, ',');
    std::getline(row, a_mid, ',');
    std::getline(row, u_mid, ',');
    std::getline(row, p_end, ',');
    EXPECT_NEAR(std::stod(p_mid), 10 * 133.322, 1e-6);
    EXPECT_NEAR(std::stod(p_end), 10 * 133.322, 1e-6);
  }
}

// ---- (b) steady flow ---------------------------------------------------------------------------

namespace {

// The steady 1D model of a tapered vessel with the law along it, integrated upstream from the
// outlet's pressure by RK4 over n steps:
//   d/dx (alpha Q^2 / A) + (A / rho) dp/dx = -k mu Q / (rho A),  A = A(p(x), x), so with
//   A' = A_p p' + A_x:  p' (A / rho - alpha Q^2 A_p / A^2) = -k mu Q / (rho A) + alpha Q^2 A_x / A^2.
// Returns p at the fractions `at` (ascending; the last must be 0, the inlet).
std::vector<double> steady_profile(const PulseSolver& s, double length, double viscosity, double q, double p_outlet,
                                   const std::vector<double>& at, int n = 4000) {
  const double rho_ = s.blood().density, alpha = s.blood().alpha, k = friction_coefficient(alpha);
  auto slope = [&](double x, double p) {  // x in metres
    const double f = x / length, dx = 1e-6;
    const TubeLaw law = s.law_at(0, f);
    const double a = law.area(p), a_p = 2 * std::sqrt(a) / law.beta;
    const double a_x = (s.law_at(0, f + dx / length).area(p) - s.law_at(0, f - dx / length).area(p)) / (2 * dx);
    return (-k * viscosity * q / (rho_ * a) + alpha * q * q * a_x / (a * a)) / (a / rho_ - alpha * q * q * a_p / (a * a));
  };
  std::vector<double> out(at.size());
  double p = p_outlet, x = length;
  const double dx = -length / n;
  std::size_t next = at.size();
  // Fill `at` from the back (largest fraction first) as x passes them.
  for (int i = 0; i <= n; ++i) {
    while (next > 0 && std::abs(x - at[next - 1] * length) < 0.5 * std::abs(dx)) out[--next] = p;
    if (i == n) break;
    const double k1 = slope(x, p), k2 = slope(x + 0.5 * dx, p + 0.5 * dx * k1), k3 = slope(x + 0.5 * dx, p + 0.5 * dx * k2),
                 k4 = slope(x + dx, p + dx * k3);
    p += dx / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    x += dx;
  }
  return out;
}

struct SteadyState {
  double inlet_pressure = 0, last_change = 0;
};

SteadyState run_to_steady(PulseSolver& s, double duration) {
  const auto steps = static_cast<std::size_t>(std::ceil(duration / s.dt()));
  double before = 0;
  for (std::size_t k = 0; k < steps; ++k) {
    s.step();
    if (k + 1 == steps - steps / 10) before = s.pressure_at(0, 0.0);
  }
  return {s.pressure_at(0, 0.0), std::abs(s.pressure_at(0, 0.0) - before)};
}

}  // namespace

// A compliant tapered vessel (c0 = 5 m/s at the inlet, the diameter falling by 40 %) into a
// resistance: the inlet pressure and the area profile of the 1D solver agree with the
// steady 1D model to 1e-6 of the vessel's pressure drop. The profile (1/D^4 rises 7.7-fold
// along it) converges spectrally in the degree: measured, the jump of Q between the traces
// and the end states is 8e-5, 4e-6, 2e-7 and 1e-9 of Q at degrees 5, 7, 9 and 12, and at
// degree 9 the inlet pressure is 2e-7 of the drop from the steady model's.
TEST(TaperedVessels, SteadyFlowMatchesTheSteadyModel) {
  const double d0 = 0.5e-3, d1 = 0.3e-3, length = 0.05, viscosity = 4e-3, q = 1e-8;
  const double r_out = 3e10, p_out = 1333.0;
  Network net = tapered_vessel(length, d0, d1, beta_for_wave_speed(5.0, pi / 4 * d0 * d0), p_out, newtonian(viscosity));
  net.outlets.push_back(resistance_outlet(0, r_out, p_out));
  net.inlet = Inlet{0, constant_flow(q)};
  SolverOptions o;
  o.degree = 9;
  o.start = StartChoice::rest;
  PulseSolver s(net, o);
  const SteadyState run = run_to_steady(s, 2.0);
  const std::vector<double> at = {0.0, 0.25, 0.5, 0.75, 1.0};
  const std::vector<double> p = steady_profile(s, length, viscosity, q, p_out + r_out * q, at);
  const double drop = p[0] - p.back();
  const double rigid = tapered_poiseuille_resistance(viscosity, length, d0, d1, 4.0 / 3.0) * q;
  std::printf("[ steady ] tapered compliant: inlet %.9f Pa, steady model %.9f Pa (rel. to drop %.2e), drop %.3f Pa, "
              "rigid taper's %.3f Pa, last change %.1e Pa\n",
              run.inlet_pressure, p[0], std::abs(run.inlet_pressure - p[0]) / drop, drop, rigid, run.last_change);
  EXPECT_LT(run.last_change, 1e-8 * drop);
  EXPECT_NEAR(run.inlet_pressure, p[0], 1e-6 * drop);
  EXPECT_NEAR(s.pressure_at(0, 1.0), p.back(), 1e-6 * drop);
  for (std::size_t i = 0; i < at.size(); ++i) {
    const double expected_area = s.law_at(0, at[i]).area(p[i]);
    EXPECT_NEAR(s.area_at(0, at[i]), expected_area, 1e-7 * expected_area) << "at x = " << at[i];
    EXPECT_NEAR(s.flow_at(0, at[i]), q, 1e-6 * q);
  }
  EXPECT_GT(std::abs(rigid - drop), 1e-2 * drop);  // the compliance matters: the comparison is sharp
}

// A stiff tapered tube (c0 = 1000 m/s: the lumen departs from its reference by < 1e-6): the
// drop is the closed-form tapered Poiseuille resistance times Q plus the convective term
// alpha rho Q^2 (1/A1^2 - 1/A0^2) / 2 (the flow accelerates into the narrower end). The
// compliance changes the resistance by 4 |dA|/A < 4e-6 of it; 1e-5 of the drop bounds it.
TEST(TaperedVessels, StiffTaperGivesTheClosedFormResistance) {
  const double d0 = 0.5e-3, d1 = 0.3e-3, length = 0.05, viscosity = 4e-3, q = 1e-9;
  const double a0 = pi / 4 * d0 * d0, a1 = pi / 4 * d1 * d1, alpha = 4.0 / 3.0;
  const double r_taper = tapered_poiseuille_resistance(viscosity, length, d0, d1, alpha);
  const double r_out = r_taper, p_out = 0.0;
  Network net = tapered_vessel(length, d0, d1, beta_for_wave_speed(1000.0, a0), 0.0, newtonian(viscosity));
  net.outlets.push_back(resistance_outlet(0, r_out, p_out));
  net.inlet = Inlet{0, constant_flow(q)};
  SolverOptions o;
  o.degree = 3;
  o.start = StartChoice::rest;
  PulseSolver s(net, o);
  const SteadyState run = run_to_steady(s, 0.12);
  const double convective = alpha * rho * q * q * (1 / (a1 * a1) - 1 / (a0 * a0)) / 2;
  const double expected = p_out + q * (r_out + r_taper) + convective;
  const double drop = expected - (p_out + q * r_out);
  std::printf("[ steady ] stiff taper: inlet %.9f Pa, closed form %.9f Pa (convective part %.2e Pa), rel. error %.2e "
              "of the drop, last change %.1e Pa\n",
              run.inlet_pressure, expected, convective, std::abs(run.inlet_pressure - expected) / drop, run.last_change);
  EXPECT_NEAR(run.inlet_pressure, expected, 1e-5 * drop);
  EXPECT_NEAR(s.pressure_at(0, 1.0), p_out + q * r_out, 1e-5 * drop);
}

// ---- (c) a pulse through a short taper ----------------------------------------------------------

namespace {

// A 2 m uniform tube of diameter d0 (20 vessels), a taper to d1 of length taper_length (or
// none: a junction), a 3 m tube of d1 with a non-reflecting end. The Boileau et al. (2015)
// wall (beta ~ 1/A: E h constant), inviscid, a Gaussian pulse of 20 ms. Returns the peak
// pressures of the incident pulse at 1 m and the transmitted one at 1 m past the taper.
struct Peaks {
  double incident = 0, transmitted = 0;
};
Peaks pulse_through(double d0, double d1, double taper_length, int taper_pieces) {
  const double youngs = 400e3, thickness = 1.5e-3;
  auto beta_of = [&](double d) { return 4.0 / 3.0 * std::sqrt(pi) * youngs * thickness / (pi / 4 * d * d); };
  Network net;
  int node = 0;
  net.add_node(node);
  std::vector<double> distal;
  auto add = [&](double length, double da, double db, bool tapered) {
    const auto id = static_cast<std::int64_t>(net.vessel_count());
    net.add_node(++node);
    net.add_vessel(id, node - 1, node, length, da, 0.1 * da, 1e6, 0);
    net.beta.push_back(beta_of(da));
    net.reference_pressure.push_back(0.0);
    distal.push_back(tapered ? db : std::numeric_limits<double>::quiet_NaN());
  };
  for (int k = 0; k < 20; ++k) add(0.1, d0, d0, false);
  for (int k = 0; k < taper_pieces; ++k) {
    const double da = d0 + (d1 - d0) * k / taper_pieces, db = d0 + (d1 - d0) * (k + 1) / taper_pieces;
    if (taper_length > 0) add(taper_length / taper_pieces, da, db, true);
  }
  for (int k = 0; k < 30; ++k) add(0.1, d1, d1, false);
  net.distal_diameter = distal;
  net.blood = newtonian(0.0);
  net.inlet = Inlet{0, tabulate([](double t) { return 1e-6 * std::exp(-0.5 * std::pow((t - 0.1) / 0.02, 2)); }, 0.2,
                                4001, 10.0)};
  net.outlets.push_back(reflection_outlet(static_cast<std::int32_t>(net.vessel_count() - 1), 0.0));
  SolverOptions o;
  o.degree = 7;
  o.start = StartChoice::rest;
  PulseSolver s(net, o);
  Peaks peaks;
  const std::size_t probe_in = 10, probe_out = net.vessel_count() - 20;  // 1 m before and after the taper
  while (s.time() < 0.75) {
    s.step();
    peaks.incident = std::max(peaks.incident, s.pressure_at(probe_in, 0.0));
    peaks.transmitted = std::max(peaks.transmitted, s.pressure_at(probe_out, 0.0));
  }
  return peaks;
}

}  // namespace

// The taper (1 cm) is short against the pulse (sigma c0 = 12 cm): linear theory transmits
// the pressure amplitude 2 Y0 / (Y0 + Y1), Y = A / (rho c) the characteristic admittance;
// with beta ~ 1/A, c ~ D^(-1/2) and Y ~ D^(5/2). The taper's length against the pulse's
// (k L ~ 0.1) and the pulse's nonlinearity (u / c ~ 1e-4) are second-order effects: measured
// 3e-5, held to 1e-3.
TEST(TaperedVessels, ShortTaperTransmitsAsLinearTheory) {
  const double d0 = 20e-3, d1 = 16e-3;
  const Peaks taper = pulse_through(d0, d1, 0.01, 1);
  const double y_ratio = std::pow(d1 / d0, 2.5), transmission = 2 / (1 + y_ratio);
  const double measured = taper.transmitted / taper.incident;
  std::printf("[ wave ] short taper: transmitted / incident %.5f, linear theory %.5f (rel. %.2e)\n", measured,
              transmission, std::abs(measured / transmission - 1));
  EXPECT_NEAR(measured, transmission, 1e-3 * transmission);
}

// ---- (d) the 0D tapered vessel and the closed forms ---------------------------------------------

TEST(TaperedVessels, RuleAndClosedFormsAgreeWithQuadrature) {
  const GaussLegendre rule = gauss_legendre(8);
  for (int i = 0; i < 8; ++i) {
    EXPECT_NEAR(taper_rule_nodes[static_cast<std::size_t>(i)], 0.5 * (rule.nodes(i) + 1), 1e-15);
    EXPECT_NEAR(taper_rule_weights[static_cast<std::size_t>(i)], 0.5 * rule.weights(i), 1e-15);
  }
  const double length = 2e-3, d0 = 12e-6, d1 = 6e-6, mu = 3.5e-3, alpha = 4.0 / 3.0, k = friction_coefficient(alpha);
  auto diameter = [&](double x) { return d0 + (d1 - d0) * x / length; };
  auto area = [&](double x) { return pi / 4 * diameter(x) * diameter(x); };
  const double r = simpson([&](double x) { return k * mu / (area(x) * area(x)); }, length);
  EXPECT_NEAR(tapered_poiseuille_resistance(mu, length, d0, d1, alpha), r, 1e-12 * r);
  EXPECT_DOUBLE_EQ(tapered_poiseuille_resistance(mu, length, d0, d0, alpha), poiseuille_resistance(mu, length, d0, alpha));
  // Pries viscosity, integrated along the vessel (it rises by 2.2x towards the narrow end).
  Blood blood;
  blood.rheology = Rheology::pries;
  auto pries = [&](double d) { return apparent_viscosity(blood, d); };
  const double r_pries = simpson([&](double x) { return k * pries(diameter(x)) / (area(x) * area(x)); }, length);
  const double r_mean_diameter = poiseuille_resistance(pries(0.5 * (d0 + d1)), length, 0.5 * (d0 + d1), alpha);
  std::printf("[ 0D ] Pries taper 12 -> 6 um: integrated %.6e, closed form at mean-diameter viscosity %.6e, uniform "
              "mean diameter %.6e Pa s/m^3\n",
              r_pries, tapered_poiseuille_resistance(pries(0.5 * (d0 + d1)), length, d0, d1, alpha), r_mean_diameter);
  EXPECT_NEAR(tapered_poiseuille_resistance(pries, length, d0, d1, alpha), r_pries, 1e-7 * r_pries);
  const double inertance = simpson([&](double x) { return rho / area(x); }, length);
  EXPECT_NEAR(tapered_inertance(rho, length, d0, d1), inertance, 1e-12 * inertance);
  const double h = 1e-6, e = 160e3, nu = 0.5;
  const double compliance = simpson(
      [&](double x) {
        const TubeLaw law = thin_wall_tube_law({diameter(x), h, e}, 0.0);
        return law.compliance_per_length(law.reference_area);
      },
      length);
  EXPECT_NEAR(thin_wall_tapered_compliance(length, d0, d1, h, e, nu), compliance, 1e-12 * compliance);
}

// The 0D model of a tapered capillary (thin wall, Pries blood): its R at a uniform pressure,
// its L and its C at rest and distended, against Simpson's rule along it with the law at every
// point: all three come from 8-point rules of smooth integrands (measured 6e-10 for R, 4e-8
// for L, 4e-15 for C), held to 1e-9, 1e-7 and 1e-12.
TEST(TaperedVessels, LumpedTaperedVesselAgainstQuadrature) {
  const double length = 1e-3, d0 = 10e-6, d1 = 6e-6, h = 0.8e-6, e = 160e3, p_ext = 10 * 133.322;
  Network net;
  net.add_node(0);
  net.add_node(1);
  net.add_vessel(0, 0, 1, length, d0, h, e, 0);
  net.distal_diameter = {d1};
  Blood blood;
  blood.rheology = Rheology::pries;
  net.blood = blood;
  net.outlets.push_back(resistance_outlet(0, 1e15, p_ext));
  VesselTaper taper;
  taper.d0 = d0;
  taper.d1 = d1;
  taper.length = length;
  taper.density = blood.density;
  taper.alpha = blood.alpha;
  taper.wall = {d0, h, e};
  taper.model = WallModel::thin;
  taper.external_pressure = p_ext;
  const std::vector<TubeLaw> laws = {taper.at(0)};
  const ViscosityTable viscosity(blood);
  const std::vector<std::int32_t> taper_of = {0};
  const std::vector<VesselTaper> tapers = {taper};
  const LumpedVessels lumped(net, laws, viscosity, blood, {true}, taper_of, tapers);
  const double k = friction_coefficient(blood.alpha);
  for (const double p : {p_ext, p_ext + 40 * 133.322}) {
    auto area = [&](double x) { return taper.at(x / length).area(p); };
    const double r = simpson([&](double x) { return k * viscosity(area(x)) / (area(x) * area(x)); }, length);
    const double l = simpson([&](double x) { return blood.density / area(x); }, length);
    const double c = simpson([&](double x) { return 2 * std::sqrt(area(x)) / taper.at(x / length).beta; }, length);
    std::printf("[ 0D ] tapered capillary at %.0f Pa: R %.3e (rel. %.1e), L %.3e (rel. %.1e), C %.3e (rel. %.1e)\n", p,
                r, lumped.tapered_resistance(0, p, p) / r - 1, l, lumped.tapered_inertance(0, p, p) / l - 1, c,
                lumped.tapered_compliance(0, p) / c - 1);
    EXPECT_NEAR(lumped.tapered_resistance(0, p, p), r, 1e-9 * r);
    EXPECT_NEAR(lumped.tapered_inertance(0, p, p), l, 1e-7 * l);
    EXPECT_NEAR(lumped.tapered_compliance(0, p), c, 1e-12 * c);
  }
}

// ---- (e) N uniform pieces approach the taper -------------------------------------------------------

// The compliant tapered vessel of SteadyFlowMatchesTheSteadyModel, and chains of N uniform
// pieces of it (each at its midpoint's diameter and beta): the steady inlet pressures converge
// to the tapered vessel's, the error falling about fourfold per doubling of N (midpoint rule).
// The taper at degree 9 and the pieces at degree 5 are resolved far below these differences.
// One difference does not vanish: the junctions between pieces conserve p + rho u^2 / 2
// whatever alpha (§4), where the taper's momentum flux changes p by alpha rho Q^2 / 2 times
// the change of 1/A^2; the limit is off by (alpha - 1) times that, 8.7e-4 of the drop at
// Q = 1e-8, so the flow here is 1e-9 (8.7e-5).
TEST(TaperedVessels, UniformPiecesConvergeToTheTaper) {
  const double d0 = 0.5e-3, d1 = 0.3e-3, length = 0.05, viscosity = 4e-3, q = 1e-9;
  const double r_out = 3e10, p_out = 1333.0, beta0 = beta_for_wave_speed(5.0, pi / 4 * d0 * d0);
  auto inlet_pressure = [&](Network net, int degree) {
    net.outlets.push_back(resistance_outlet(static_cast<std::int32_t>(net.vessel_count() - 1), r_out, p_out));
    net.inlet = Inlet{0, constant_flow(q)};
    SolverOptions o;
    o.degree = degree;
    o.start = StartChoice::rest;
    PulseSolver s(net, o);
    return run_to_steady(s, 1.5).inlet_pressure;
  };
  const double tapered = inlet_pressure(tapered_vessel(length, d0, d1, beta0, p_out, newtonian(viscosity)), 9);
  const double drop = tapered - (p_out + r_out * q);
  std::vector<double> errors;
  for (const int n : {2, 4, 8, 16}) {
    Network net = chain(n, length, d0, beta0, p_out, newtonian(viscosity));
    for (int i = 0; i < n; ++i) {
      const double d = d0 + (d1 - d0) * (i + 0.5) / n;
      net.diameter[static_cast<std::size_t>(i)] = d;
      net.beta[static_cast<std::size_t>(i)] = beta0 * (d0 / d) * (d0 / d);
    }
    errors.push_back(std::abs(inlet_pressure(net, 5) - tapered) / drop);
    std::printf("[ pieces ] %d uniform pieces: inlet pressure off the taper's by %.3e of the drop\n", n, errors.back());
  }
  for (std::size_t i = 0; i + 1 < errors.size(); ++i) EXPECT_GT(errors[i] / errors[i + 1], 3.4);
  EXPECT_LT(errors.back(), 1.5e-3);  // 5.6e-2 / 8^2 and the junctions' 1e-4
}

// The stiff taper of StiffTaperGivesTheClosedFormResistance as one 0D vessel: its steady
// inlet pressure is p_out + Q (R_out + R_taper) (the 0D vessel has no convective term), to
// the compliance's 4 |dA|/A < 4e-6 of the drop.
TEST(TaperedVessels, LumpedStiffTaperGivesTheClosedFormResistance) {
  const double d0 = 0.5e-3, d1 = 0.3e-3, length = 0.05, viscosity = 4e-3, q = 1e-9;
  const double r_taper = tapered_poiseuille_resistance(viscosity, length, d0, d1, 4.0 / 3.0);
  Network net = tapered_vessel(length, d0, d1, beta_for_wave_speed(1000.0, pi / 4 * d0 * d0), 0.0, newtonian(viscosity));
  net.outlets.push_back(resistance_outlet(0, r_taper, 0.0));
  net.inlet = Inlet{0, constant_flow(q)};
  SolverOptions o;
  o.model = ModelChoice::zero_d;
  o.start = StartChoice::rest;
  PulseSolver s(net, o);
  ASSERT_TRUE(s.is_lumped(0));
  for (int k = 0; k < 40; ++k) s.step();  // 0D steps of 1 s: the 10 ms ramp, then steady
  const double expected = q * 2 * r_taper, drop = q * r_taper;
  std::printf("[ 0D ] stiff taper: inlet %.9f Pa, closed form %.9f Pa (rel. %.2e of the drop)\n", s.pressure_at(0, 0.0),
              expected, std::abs(s.pressure_at(0, 0.0) - expected) / drop);
  EXPECT_NEAR(s.pressure_at(0, 0.0), expected, 1e-5 * drop);
  EXPECT_NEAR(s.pressure_at(0, 1.0), q * r_taper, 1e-5 * drop);
  // The interior follows the rigid taper's profile: at the middle, the share of the
  // resistance built by then (1/D^3 linear in it).
  const double dm = 0.5 * (d0 + d1);
  const double share = (1 / std::pow(d0, 3) - 1 / std::pow(dm, 3)) / (1 / std::pow(d0, 3) - 1 / std::pow(d1, 3));
  EXPECT_NEAR(s.pressure_at(0, 0.5), expected - share * drop, 1e-5 * drop);
}
