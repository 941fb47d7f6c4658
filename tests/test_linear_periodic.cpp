// The periodic state by harmonics (harmonic/): the complex nodal system against a dense
// solve, a waveform's Fourier series, and the network's linear response against closed
// forms: the input impedance of a uniform tube ending in a Windkessel, and its lumped
// limits, the RC and RLC circuits a short vessel makes with its outlet.
#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "harmonic/fourier_series.hpp"
#include "harmonic/linear_periodic.hpp"
#include "network_builders.hpp"
#include "network_flow/harmonic_system.hpp"

namespace hemotree {
namespace {

using namespace test_networks;
using C = std::complex<double>;

std::vector<C> dense_solve(std::size_t nodes, const std::vector<std::int32_t>& a, const std::vector<std::int32_t>& b,
                           const std::vector<C>& y, const std::vector<C>& s, const std::vector<C>& rhs) {
  Eigen::MatrixXcd m = Eigen::MatrixXcd::Zero(static_cast<Eigen::Index>(nodes), static_cast<Eigen::Index>(nodes));
  for (std::size_t i = 0; i < nodes; ++i) m(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i)) += s[i];
  for (std::size_t e = 0; e < a.size(); ++e) {
    m(a[e], a[e]) += y[e];
    m(b[e], b[e]) += y[e];
    m(a[e], b[e]) -= y[e];
    m(b[e], a[e]) -= y[e];
  }
  const Eigen::VectorXcd x = m.fullPivLu().solve(Eigen::Map<const Eigen::VectorXcd>(rhs.data(), static_cast<Eigen::Index>(nodes)));
  return {x.data(), x.data() + x.size()};
}

// A tree of 7 nodes (elimination) and the same with a loop closed (sparse LU), complex
// admittances and shunts of a line's kind (series with a phase, shunts mostly capacitive).
TEST(HarmonicSystem, TreeEliminationAndSparseLuMatchADenseSolve) {
  std::vector<std::int32_t> a{0, 0, 1, 1, 2, 2}, b{1, 2, 3, 4, 5, 6};
  std::vector<C> y{{2, -1}, {1.5, -0.3}, {0.7, -0.2}, {3, -2}, {1, -0.1}, {0.4, -0.4}};
  const std::vector<C> s{{0, 0.1}, {0, 0.05}, {0, 0.2}, {0.5, 0.1}, {0.8, 0.02}, {0.3, 0.3}, {1.2, 0}};
  const std::vector<C> rhs{{1, 0}, {0, 0}, {0, 0.5}, {0, 0}, {-0.2, 0}, {0, 0}, {0.1, -0.1}};
  for (const bool loop : {false, true}) {
    if (loop) {
      a.push_back(3);
      b.push_back(6);
      y.emplace_back(0.9, -0.6);
    }
    const std::vector<C> x = solve_harmonic_system(7, a, b, y, s, rhs), expected = dense_solve(7, a, b, y, s, rhs);
    for (std::size_t i = 0; i < 7; ++i) EXPECT_LT(std::abs(x[i] - expected[i]), 1e-13 * std::abs(expected[0])) << "node " << i << " loop " << loop;
  }
}

TEST(HarmonicSystem, APartWithNoPathToGroundIsRefused) {
  const std::vector<std::int32_t> a{0}, b{1};
  const std::vector<C> y{{1, -1}}, s{0, 0}, rhs{1, 0};
  EXPECT_THROW(solve_harmonic_system(2, a, b, y, s, rhs), std::invalid_argument);
}

TEST(FourierSeries, ATabulatedCosineHasItsAmplitudeAndPhase) {
  const double period = 0.8, w = 2 * std::numbers::pi / period;
  const Waveform wave = tabulate([&](double t) { return 3.0 + 2.0 * std::cos(w * t - 0.4) + 0.5 * std::sin(3 * w * t); },
                                 period, 4097, period);
  const FourierSeries f = fourier_series(wave, 4);
  // The table's linear interpolation departs from the cosine by (dt w)^2 / 8 of it: 3e-7.
  EXPECT_NEAR(f.amplitude[0].real(), 3.0, 1e-6);
  EXPECT_NEAR(std::abs(f.amplitude[1] - std::polar(2.0, -0.4)), 0.0, 2e-6);
  EXPECT_NEAR(std::abs(f.amplitude[3] - C(0, -0.5)), 0.0, 2e-6);
  EXPECT_NEAR(std::abs(f.amplitude[2]), 0.0, 1e-6);
  EXPECT_NEAR(f(0.3), 3.0 + 2.0 * std::cos(w * 0.3 - 0.4) + 0.5 * std::sin(3 * w * 0.3), 1e-5);
}

std::vector<TubeLaw> laws_of(const Network& net) {
  std::vector<TubeLaw> laws(net.vessel_count());
  for (std::size_t v = 0; v < laws.size(); ++v) {
    laws[v].beta = net.beta[v];
    laws[v].reference_area = std::numbers::pi / 4 * net.diameter[v] * net.diameter[v];
    laws[v].reference_pressure = net.reference_pressure[v];
    laws[v].density = rho;
    laws[v].alpha = 4.0 / 3.0;
  }
  return laws;
}

// One vessel (or a chain of them), fed a mean flow with a pulse at the fundamental and the
// third harmonic, into an RCR outlet.
struct TubeIntoWindkessel {
  static constexpr double q0 = 5e-6, mu = 3.5e-3, period = 0.9;
  double r1 = 5e7, c = 1e-9, r2 = 1.5e9;
  Network net;
  std::vector<TubeLaw> laws;
  TubeIntoWindkessel(int vessels, double length, double diameter, double wave_speed) {
    const double area = std::numbers::pi / 4 * diameter * diameter;
    net = chain(vessels, length, diameter, beta_for_wave_speed(wave_speed, area), q0 * (r1 + r2), newtonian(mu));
    const double w = 2 * std::numbers::pi / period;
    net.inlet = Inlet{0, tabulate([&](double t) { return q0 * (1 + 0.3 * std::sin(w * t) + 0.1 * std::cos(3 * w * t)); },
                                  period, 2049, period)};
    net.outlets.push_back(rcr_outlet(vessels - 1, r1, c, r2, 0));
    laws = laws_of(net);
  }
  C windkessel(double w) const { return r1 + r2 / C(1, w * r2 * c); }
};

TEST(LinearPeriodic, AUniformTubesInputImpedanceIsTheTransmissionLines) {
  const TubeIntoWindkessel t(1, 0.15, 4e-3, 6.0);
  const ViscosityTable viscosity(newtonian(TubeIntoWindkessel::mu));
  const LinearPeriodic s = solve_linear_periodic(t.net, newtonian(TubeIntoWindkessel::mu), t.laws, viscosity, 5);
  const FourierSeries inflow = fourier_series(t.net.inlet->waveform, 5);
  const VesselLine& line = s.line(0);
  // The line is the vessel's at its loaded lumen: Poiseuille's 8 pi mu / A^2 (alpha = 4/3), rho / A.
  const double area = t.laws[0].area(s.mean_node_pressure()[0] / 2 + s.mean_node_pressure()[1] / 2);
  EXPECT_NEAR(line.resistance, 8 * std::numbers::pi * TubeIntoWindkessel::mu / (area * area), 1e-12 * line.resistance);
  EXPECT_NEAR(line.inertance, rho / area, 1e-12 * line.inertance);
  for (const int k : {1, 3}) {
    const double w = s.omega(k);
    const C g = line.propagation(w) * line.length, zc = line.characteristic_impedance(w), zl = t.windkessel(w);
    const C z_in = zc * (zl + zc * std::tanh(g)) / (zc + zl * std::tanh(g));
    const C expected = inflow.amplitude[static_cast<std::size_t>(k)] * z_in;
    EXPECT_LT(std::abs(s.node_pressure(k, 0) - expected), 1e-10 * std::abs(expected)) << "harmonic " << k;
    // The flow at the inlet is the inflow, at the outlet the Windkessel's share.
    EXPECT_LT(std::abs(s.flow(k, 0, 0.0) - inflow.amplitude[static_cast<std::size_t>(k)]),
              1e-10 * std::abs(inflow.amplitude[static_cast<std::size_t>(k)]));
    EXPECT_LT(std::abs(s.flow(k, 0, 1.0) - s.node_pressure(k, 1) / zl), 1e-10 * std::abs(s.flow(k, 0, 1.0)));
  }
  // The mean is the steady state: the outlet at Q0 (R1 + R2).
  EXPECT_NEAR(s.mean_node_pressure()[1], TubeIntoWindkessel::q0 * (t.r1 + t.r2), 1e-9 * s.mean_node_pressure()[1]);
}

TEST(LinearPeriodic, ATubeCutInSegmentsIsTheSameLine) {
  // Three segments of one tube: their pi circuits in series are the whole line's, up to the
  // segments' loaded lumens, which spread by the mean pressure drop along the tube:
  // d sqrt(A) / sqrt(A) = dp / (beta sqrt(A)) = dp / (2 rho c^2) =: delta (5e-4 here), and the
  // line's coefficients with them by a few delta. (At c = 6 m/s, delta = 5.5e-3 and the
  // difference 1.4e-3: a quarter of delta.)
  const double c = 20.0;
  const TubeIntoWindkessel whole(1, 0.15, 4e-3, c), cut(3, 0.15, 4e-3, c);
  const Blood blood = newtonian(TubeIntoWindkessel::mu);
  const ViscosityTable viscosity(blood);
  const LinearPeriodic a = solve_linear_periodic(whole.net, blood, whole.laws, viscosity, 3);
  const LinearPeriodic b = solve_linear_periodic(cut.net, blood, cut.laws, viscosity, 3);
  const double delta = (a.mean_node_pressure()[0] - a.mean_node_pressure()[1]) / (2 * rho * c * c);
  ASSERT_GT(delta, 1e-4);
  for (const int k : {1, 3}) {
    const double scale = std::abs(a.node_pressure(k, 0));
    EXPECT_LT(std::abs(a.node_pressure(k, 0) - b.node_pressure(k, 0)), delta * scale) << "harmonic " << k;
    // Inside the line: its points at a third and two thirds of the length are the segments' ends.
    EXPECT_LT(std::abs(a.pressure(k, 0, 1.0 / 3) - b.node_pressure(k, 1)), delta * scale) << "harmonic " << k;
    EXPECT_LT(std::abs(a.pressure(k, 0, 2.0 / 3) - b.node_pressure(k, 2)), delta * scale) << "harmonic " << k;
    EXPECT_LT(std::abs(a.flow(k, 0, 2.0 / 3) - b.flow(k, 2, 0.0)), delta * std::abs(a.flow(k, 0, 0.0))) << "harmonic " << k;
  }
}

TEST(LinearPeriodic, AShortVesselIntoAWindkesselIsTheRcAndRlcCircuit) {
  // 5 mm of a stiff 1 mm vessel: |gamma l| ~ 1e-2, so the line is its R and L in series
  // with the outlet (C l / 2 at its ends, beside the Windkessel's C, is 4e-5 of it).
  TubeIntoWindkessel t(1, 5e-3, 1e-3, 20.0);
  const Blood blood = newtonian(TubeIntoWindkessel::mu);
  const ViscosityTable viscosity(blood);
  const LinearPeriodic s = solve_linear_periodic(t.net, blood, t.laws, viscosity, 3);
  const FourierSeries inflow = fourier_series(t.net.inlet->waveform, 3);
  const VesselLine& line = s.line(0);
  for (const int k : {1, 3}) {
    const double w = s.omega(k);
    ASSERT_LT(std::abs(line.propagation(w) * line.length), 2e-2);
    const C rc = line.resistance * line.length + t.windkessel(w);
    const C rlc = rc + C(0, w * line.inertance * line.length);
    const C expected = inflow.amplitude[static_cast<std::size_t>(k)] * rlc;
    EXPECT_LT(std::abs(s.node_pressure(k, 0) - expected), 1e-3 * std::abs(expected)) << "harmonic " << k;
    // Without the inertance the error would be w L / |Z|: the test tells RLC from RC.
    EXPECT_GT(std::abs(rlc - rc), 3e-3 * std::abs(rlc)) << "harmonic " << k;
  }
}

TEST(LinearPeriodic, AHeldPressureDrivesTheLineFromItsEnd) {
  // Pressures at both ends of two segments: p(t) pulsing at the inlet, constant at the
  // outlet. The flow into the line is P coth(gamma l) / Z_c.
  const double mu = 3.5e-3, period = 1.0, w = 2 * std::numbers::pi / period, d = 3e-3, c = 20.0;
  const double area = std::numbers::pi / 4 * d * d;
  Network net = chain(2, 0.3, d, beta_for_wave_speed(c, area), 1e4, newtonian(mu));
  NodeBoundary in = pressure_boundary(0, 1.2e4);
  in.waveform = tabulate([&](double t) { return 1.2e4 + 800 * std::sin(w * t); }, period, 2049, period);
  net.boundaries = {in, pressure_boundary(2, 1.0e4)};
  const Blood blood = newtonian(mu);
  const ViscosityTable viscosity(blood);
  const std::vector<TubeLaw> laws = laws_of(net);
  const LinearPeriodic s = solve_linear_periodic(net, blood, laws, viscosity, 2);
  const C p_in = fourier_series(in.waveform, 1).amplitude[1];
  EXPECT_LT(std::abs(s.node_pressure(1, 0) - p_in), 1e-12 * std::abs(p_in));
  EXPECT_EQ(s.node_pressure(1, 2), C(0));
  // The closed form takes the first segment's line for the whole; the two lumens differ by
  // the mean drop, delta = 2e3 Pa / (2 rho c^2) = 2.4e-3 (at c = 5 m/s the flow moved by 0.97 delta).
  const double delta = 2e3 / (2 * rho * c * c);
  const VesselLine& line = s.line(0);
  const C g = line.propagation(w) * 0.3, zc = line.characteristic_impedance(w);
  const C expected = p_in / (zc * std::tanh(g));
  EXPECT_LT(std::abs(s.flow(1, 0, 0.0) - expected), 2 * delta * std::abs(expected));
  // The mean is Poiseuille's through both: the held pressures' difference over R.
  EXPECT_NEAR(s.mean_flow()[0], s.mean_flow()[1], 1e-12 * s.mean_flow()[0]);
}

}  // namespace
}  // namespace hemotree
