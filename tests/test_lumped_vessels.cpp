// The 0D vessels (pulse/lumped_vessels) against circuits solved exactly: one vessel between
// an imposed inflow and a resistance outlet is, for small pressure changes, two capacitors
// C/2 joined by R (and L), with R_out to p_out. The linear ODE of that circuit is solved
// exactly through its eigenvectors, independently of the scheme; BDF2 must follow it to its
// second order. Mass through a 0D network to round-off, and the steady
// pressure profile inside a narrowing capillary against a quadrature of its ODE.
#include <cmath>
#include <cstdint>
#include <complex>
#include <numbers>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "physics/poiseuille.hpp"
#include "physics/viscosity_table.hpp"
#include "formats/run_boundaries.hpp"
#include "pulse/lumped_vessels.hpp"
#include "tests/network_builders.hpp"

using namespace hemotree;
using namespace hemotree::test_networks;

namespace {

constexpr double pi = std::numbers::pi;

// One vessel (node 0 -> node 1) with an R outlet; the law from beta directly.
struct OneVessel {
  Network net;
  std::vector<TubeLaw> laws;
  double length = 0.01, diameter = 1e-3, beta = 0, p0 = 1e4, r_out = 0;
  double compliance = 0, resistance = 0, inertance = 0;  // of the vessel, at p0

  OneVessel(double wanted_compliance, double viscosity, double density, double outlet_resistance)
      : r_out(outlet_resistance) {
    const double area = pi / 4 * diameter * diameter, root = std::sqrt(area);
    beta = 2 * length * root / wanted_compliance;  // C = L dA/dp = 2 L sqrt(A) / beta
    Blood blood = newtonian(viscosity);
    blood.density = density;
    net = chain(1, length, diameter, beta, p0, blood);
    net.outlets.push_back(resistance_outlet(0, r_out, p0));
    net.inlet = Inlet{0, Waveform{}};  // its flow is given to predict() here
    TubeLaw law;
    law.beta = beta;
    law.reference_area = area;
    law.reference_pressure = p0;
    law.density = density;
    laws.push_back(law);
    compliance = wanted_compliance;
    resistance = 8 * pi * viscosity * length / (area * area);
    inertance = density * length / area;
  }
};

// e^(M t) x0 by M's eigenvectors: the circuits here have distinct eigenvalues.
template <int N>
Eigen::Matrix<double, N, 1> propagate(const Eigen::Matrix<double, N, N>& m, const Eigen::Matrix<double, N, 1>& x0, double t) {
  const Eigen::EigenSolver<Eigen::Matrix<double, N, N>> eigen(m);
  const auto& v = eigen.eigenvectors();
  const Eigen::Matrix<std::complex<double>, N, 1> c = v.partialPivLu().solve(x0.template cast<std::complex<double>>());
  const Eigen::Matrix<std::complex<double>, N, 1> decayed = (eigen.eigenvalues() * t).array().exp() * c.array();
  return (v * decayed).real();
}

// Exact response of the linearised circuit from rest at p0 to the inflow q (1 - e^(-t/tau)),
// smooth from zero (a step in the inflow would cost BDF2 an order: its start assumes a
// constant past). State (p_a, Q, p_b) relative to p0, and z = q e^(-t/tau):
// C/2 p_a' = q - z - Q; L Q' = p_a - p_b - R Q; C/2 p_b' = Q - p_b / R_out; z' = -z / tau.
// Without inertance (an RC) Q = (p_a - p_b) / R and the state is (p_a, p_b, z).
Eigen::Vector3d exact_response(const OneVessel& c, double q, double tau, double t, bool inertia) {
  const double h = c.compliance / 2, g = 1 / c.resistance;
  if (!inertia) {
    Eigen::Matrix3d m;
    m << -g / h, g / h, -1 / h,
         g / h, -(g + 1 / c.r_out) / h, 0,
         0, 0, -1 / tau;
    const Eigen::Vector3d f(q / h, 0, 0);
    const Eigen::Vector3d steady = -m.partialPivLu().solve(f);
    const Eigen::Vector3d x = steady + propagate<3>(m, Eigen::Vector3d(0, 0, q) - steady, t);
    return {x(0), (x(0) - x(1)) * g, x(1)};
  }
  Eigen::Matrix4d m;
  m << 0, -1 / h, 0, -1 / h,
       1 / c.inertance, -c.resistance / c.inertance, -1 / c.inertance, 0,
       0, 1 / h, -1 / (h * c.r_out), 0,
       0, 0, 0, -1 / tau;
  const Eigen::Vector4d f(q / h, 0, 0, 0);
  const Eigen::Vector4d steady = -m.partialPivLu().solve(f);
  return (steady + propagate<4>(m, Eigen::Vector4d(0, 0, 0, q) - steady, t)).head<3>();
}

// Runs the 0D vessel under that inflow for `steps` of dt; the largest error in p_a over the
// run, relative to the largest p_a.
double largest_error(const OneVessel& c, double q, double tau, double dt, int steps, bool inertia) {
  const ViscosityTable viscosity(*c.net.blood);
  LumpedVessels lumped(c.net, c.laws, viscosity, *c.net.blood, {true});
  lumped.start(std::vector<double>(c.net.node_count(), c.p0), {0.0});
  double error = 0, scale = 0;
  for (int k = 1; k <= steps; ++k) {
    const double t = k * dt;
    lumped.predict(dt, {}, q * (1 - std::exp(-t / tau)));
    lumped.complete({});
    const Eigen::Vector3d exact = exact_response(c, q, tau, t, inertia);
    error = std::max(error, std::abs(lumped.node_pressure(lumped.node_of(0)) - c.p0 - exact(0)));
    scale = std::max(scale, std::abs(exact(0)));
  }
  return error / scale;
}

}  // namespace

// An RC: the inertance negligible (a density of 1e-9 kg/m^3), R between the halves of C as
// large as R_out, so that both of the circuit's modes show. Pressure changes of 1e-3 Pa
// against beta sqrt(A) keep the tube law linear to 1e-7.
TEST(LumpedVessels, FollowTheExactResponseOfAnRcCircuit) {
  const double c = 1e-10, r = 1e9;
  const double viscosity = r * std::pow(pi / 4 * 1e-6, 2) / (8 * pi * 0.01);
  const OneVessel circuit(c, viscosity, 1e-9, r);
  const double tau = r * c / 2, q = 1e-3 / r;
  const double coarse = largest_error(circuit, q, tau, tau / 50, 250, false),
               fine = largest_error(circuit, q, tau, tau / 100, 500, false);
  std::printf("RC: largest relative error %.3g at tau/50, %.3g at tau/100 (ratio %.2f)\n", coarse, fine, coarse / fine);
  EXPECT_LT(fine, 1e-4);  // measured 1.4e-5
  EXPECT_GT(coarse / fine, 3.5);  // second order: 4
  EXPECT_LT(coarse / fine, 4.5);
}

// An RLC ringing at 5 Hz with a damping ratio of about 0.15, over three of its periods.
TEST(LumpedVessels, FollowTheExactResponseOfAnRlcCircuit) {
  const double area = pi / 4 * 1e-6, density = 1050, length = 0.01;
  const double inertance = density * length / area, omega = 2 * pi * 5;
  const double c = 2 / (inertance * omega * omega);  // omega^2 = 1 / (L C/2)
  const double r = 0.3 * std::sqrt(inertance / (c / 2));
  const double viscosity = r * area * area / (8 * pi * length);
  const OneVessel circuit(c, viscosity, density, 3 * r);
  EXPECT_NEAR(circuit.inertance, inertance, 1e-9 * inertance);
  const double period = 2 * pi / omega, q = 1e-3 / r;
  const double coarse = largest_error(circuit, q, period / 8, period / 200, 600, true),
               fine = largest_error(circuit, q, period / 8, period / 400, 1200, true);
  std::printf("RLC: largest relative error %.3g at T/200, %.3g at T/400 (ratio %.2f)\n", coarse, fine, coarse / fine);
  EXPECT_LT(fine, 3e-4);  // measured 6.7e-5
  EXPECT_GT(coarse / fine, 3.5);
  EXPECT_LT(coarse / fine, 4.5);
}

// A vessel along which the pressure diffuses (an RC line, w R C = 6 at the drive, the
// inertance negligible) in n pi sections, driven by a small sinusoidal inflow into a
// resistance outlet as large as its own: the inlet pressure's complex amplitude in the
// periodic state against the uniform line's input impedance,
// Z = Z_c (R_out + Z_c tanh(g)) / (Z_c + R_out tanh(g)), g = sqrt(i w R C), Z_c = sqrt(R / (i w C)).
// A pi section is the line to second order in its length: the error falls as 1 / n^2.
namespace {

double sectioned_line_error(int sections) {
  const double c = 1e-10, r = 1e9, omega = 6 / (r * c), period = 2 * pi / omega;
  const double viscosity = r * std::pow(pi / 4 * 1e-6, 2) / (8 * pi * 0.01);
  const OneVessel line(c, viscosity, 1e-9, r);
  const ViscosityTable mu(*line.net.blood);
  const std::vector<std::uint8_t> cut{static_cast<std::uint8_t>(sections)};
  LumpedVessels lumped(line.net, line.laws, mu, *line.net.blood, {true}, {}, {}, cut);
  EXPECT_EQ(lumped.sections(0), static_cast<std::size_t>(sections));
  EXPECT_EQ(lumped.node_count(), static_cast<std::size_t>(1 + sections));
  lumped.start(std::vector<double>(line.net.node_count(), line.p0), {0.0});
  const int per_period = 1000, periods = 24;
  const double dt = period / per_period, q = 1e-3 / r;
  std::complex<double> sum = 0;
  for (int k = 1; k <= periods * per_period; ++k) {
    const double t = k * dt;
    lumped.predict(dt, {}, q * std::sin(omega * t));
    lumped.complete({});
    if (k > (periods - 1) * per_period)
      sum += (lumped.node_pressure(lumped.node_of(0)) - line.p0) * std::exp(std::complex<double>(0, -omega * t));
  }
  const std::complex<double> amplitude = std::complex<double>(0, 2) * sum / static_cast<double>(per_period);
  const std::complex<double> i(0, 1), g = std::sqrt(i * omega * r * c), zc = std::sqrt(r / (i * omega * c));
  const std::complex<double> z = zc * (line.r_out + zc * std::tanh(g)) / (zc + line.r_out * std::tanh(g));
  return std::abs(amplitude - z * q) / std::abs(z * q);
}

}  // namespace

TEST(LumpedVessels, ADiffusiveVesselInSectionsFollowsItsLine) {
  double error[4];
  for (int j = 0; j < 4; ++j) error[j] = sectioned_line_error(1 << j);
  std::printf("RC line, w R C = 6: inlet impedance off by %.3g (1 section), %.3g (2), %.3g (4), %.3g (8)\n", error[0],
              error[1], error[2], error[3]);
  EXPECT_LT(error[3], 0.02);  // measured 0.0123; one section 0.51
  for (int j = 1; j < 3; ++j) {  // second order: a quarter with each halving
    EXPECT_GT(error[j] / error[j + 1], 3.5) << j;
    EXPECT_LT(error[j] / error[j + 1], 4.5) << j;
  }
}

// A bifurcation of 0D vessels with an RCR and an R outlet under a pulsating inflow: what came
// in, less what left, is what the vessels hold, to round-off, every step; and the nonlinear
// tube law is exercised (pressures change by a tenth of beta sqrt(A)).
namespace {

// A root and two daughters, every one 0D, into an RCR outlet and an R outlet.
struct ThreeVessels {
  Blood blood = newtonian(3.5e-3);
  Network net;
  std::vector<TubeLaw> laws = std::vector<TubeLaw>(3);
  double area = 0, beta = 0;
  ThreeVessels() {
    for (int k = 0; k < 4; ++k) net.add_node(k);
    const double d = 1e-3;
    area = pi / 4 * d * d;
    net.add_vessel(0, 0, 1, 0.02, d, 1e-4, 1e6, 0);
    net.add_vessel(1, 1, 2, 0.01, 0.8 * d, 1e-4, 1e6, 1);
    net.add_vessel(2, 1, 3, 0.015, 0.7 * d, 1e-4, 1e6, 1);
    beta = beta_for_wave_speed(5, area);
    net.beta.assign(3, beta);
    net.reference_pressure.assign(3, 1e4);
    net.blood = blood;
    net.outlets.push_back(rcr_outlet(1, 1e8, 1e-10, 1e9, 1e3));
    net.outlets.push_back(resistance_outlet(2, 2e9, 1e3));
    net.inlet = Inlet{0, Waveform{}};
    for (std::size_t v = 0; v < 3; ++v) {
      laws[v].beta = beta;
      laws[v].reference_area = pi / 4 * net.diameter[v] * net.diameter[v];
      laws[v].reference_pressure = 1e4;
      laws[v].density = blood.density;
    }
  }
};

// Two seconds of a pulsating inflow from rest: the largest |in - out - (stored - stored at
// the start)| over the steps, relative to what came in (in: the boundaries whose volume is
// positive, the inlet; out: the others).
double largest_mass_error(LumpedVessels& lumped, const Network& net) {
  const double v0 = lumped.stored_volume();
  std::vector<double> through(RunBoundaries(net).size(), 0.0);  // per boundary, in
  double worst = 0;
  for (int k = 0; k < 2000; ++k) {
    const double t = (k + 1) * 1e-3;
    lumped.predict(1e-3, {}, 5e-6 * (1 + std::sin(2 * pi * t)));
    lumped.complete({}, through);
    double in = 0, net_in = 0;
    for (const double v : through) {
      in += std::max(v, 0.0);
      net_in += v;
    }
    worst = std::max(worst, std::abs(net_in - (lumped.stored_volume() - v0)) / in);
  }
  return worst;
}

}  // namespace

TEST(LumpedVessels, ConserveMassToRoundOff) {
  const ThreeVessels three;
  const Network& net = three.net;
  const std::vector<TubeLaw>& laws = three.laws;
  const Blood& blood = three.blood;
  const double area = three.area, beta = three.beta;
  const ViscosityTable viscosity(blood);
  LumpedVessels lumped(net, laws, viscosity, blood, {true, true, true});
  lumped.start(std::vector<double>(net.node_count(), 1e4), {0.0, 0.0, 0.0});
  const double worst = largest_mass_error(lumped, net);
  const double swing = std::abs(lumped.node_pressure(lumped.node_of(0)) - 1e4) / (beta * std::sqrt(area));
  std::printf("0D mass: largest |in - out - stored| / in %.3g; pressure swing %.3g of beta sqrt(A)\n", worst, swing);
  EXPECT_LT(worst, 1e-12);
  EXPECT_GT(swing, 0.05);
}

// The same with the vessels in 3, 1 and 2 sections (inner nodes hold volume of their own;
// the RCR outlet sits at the last section of the first daughter): the stored volume counts
// them, and the pressure and flow along a vessel read its sections.
TEST(LumpedVessels, ConserveMassToRoundOffInSections) {
  const ThreeVessels three;
  const ViscosityTable viscosity(three.blood);
  const std::vector<std::uint8_t> cut{3, 1, 2};
  LumpedVessels lumped(three.net, three.laws, viscosity, three.blood, {true, true, true}, {}, {}, cut);
  EXPECT_TRUE(lumped.sectioned());
  EXPECT_EQ(lumped.node_count(), 4u + 1u + 3u);  // network nodes, the capacitor, inner nodes
  lumped.start(std::vector<double>(three.net.node_count(), 1e4), {0.0, 0.0, 0.0});
  const double worst = largest_mass_error(lumped, three.net);
  std::printf("0D mass in sections: largest |in - out - stored| / in %.3g\n", worst);
  EXPECT_LT(worst, 1e-12);
  const std::int32_t root = lumped.vessel_index(0);
  EXPECT_EQ(lumped.pressure_at(root, 0), lumped.node_pressure(lumped.from_node(root)));
  EXPECT_EQ(lumped.pressure_at(root, 1), lumped.node_pressure(lumped.to_node(root)));
  const double p_first = lumped.pressure_at(root, 1.0 / 3), p_second = lumped.pressure_at(root, 2.0 / 3);
  EXPECT_GT(lumped.pressure_at(root, 0), p_first);  // falling along it, through its inner nodes
  EXPECT_GT(p_first, p_second);
  EXPECT_GT(p_second, lumped.pressure_at(root, 1));
  EXPECT_GT(lumped.flow(root), 0.0);
}

// A vessel drained far faster than it fills (the outflow of a second's inflow each step): its
// lumen closes, and the step that would linearise about a closed lumen says which vessel,
// instead of handing the nodal system a negative compliance.
TEST(LumpedVessels, NameTheVesselWhoseLumenCloses) {
  const ThreeVessels three;
  const ViscosityTable viscosity(three.blood);
  LumpedVessels lumped(three.net, three.laws, viscosity, three.blood, {true, true, true});
  lumped.start(std::vector<double>(three.net.node_count(), 1e4), {0.0, 0.0, 0.0});
  bool named = false;
  for (int k = 0; k < 50 && !named; ++k) {
    try {
      lumped.predict(1e-3, {}, -5e-3);
      lumped.complete({});
    } catch (const LumpedVessels::CollapsedNode& collapsed) {
      named = true;
      EXPECT_EQ(collapsed.vessel, 0);  // the root, at the inlet's node
      std::printf("lumen closed at step %d, vessel %d named\n", k, collapsed.vessel);
    }
  }
  EXPECT_TRUE(named);
}

// The step's working arrays freed between steps (a run's cycle ends) and made again: the
// same state, bit for bit, as never freeing them, the RCR outlet's R1 edge included.
TEST(LumpedVessels, StepAfterReleasingTheStepArraysToTheSameBits) {
  const ThreeVessels three;
  const ViscosityTable viscosity(three.blood);
  LumpedVessels kept(three.net, three.laws, viscosity, three.blood, {true, true, true});
  LumpedVessels released(three.net, three.laws, viscosity, three.blood, {true, true, true});
  for (LumpedVessels* l : {&kept, &released}) l->start(std::vector<double>(three.net.node_count(), 1e4), {0.0, 0.0, 0.0});
  std::vector<double> through[2];  // per boundary, in
  for (auto& t : through) t.assign(RunBoundaries(three.net).size(), 0.0);
  for (int k = 0; k < 300; ++k) {
    const double t = (k + 1) * 1e-3, inflow = 5e-6 * (1 + std::sin(2 * pi * t));
    if (k % 7 == 3) released.release_step_arrays();
    kept.predict(1e-3, {}, inflow);
    kept.complete({}, through[0]);
    released.predict(1e-3, {}, inflow);
    released.complete({}, through[1]);
  }
  for (std::int32_t n = 0; n < static_cast<std::int32_t>(kept.node_count()); ++n)
    EXPECT_EQ(released.node_pressure(n), kept.node_pressure(n)) << "node " << n;
  for (std::int32_t e = 0; e < 3; ++e) EXPECT_EQ(released.flow(e), kept.flow(e)) << "vessel " << e;
  EXPECT_EQ(through[1], through[0]);
  EXPECT_GT(std::abs(kept.node_pressure(kept.node_of(0)) - 1e4), 100.0);  // it moved
}

// The pressure inside a capillary whose lumen narrows along it (a drop of a tenth of
// beta sqrt(A)): where the steady ODE dp/dx = -k mu(A) Q / A^2 puts it, integrated by RK4 in
// x from the proximal pressure with the flow the two end pressures give.
TEST(LumpedVessels, PlaceTheInteriorPressureOnTheSteadyProfile) {
  Blood blood;  // Pries
  const double d = 6e-6, area = pi / 4 * d * d, length = 5e-4;
  const double beta = 2.5e4 / std::sqrt(area);  // beta sqrt(A) = 25 kPa: the drop narrows the radius 4 %
  Network net = chain(1, length, d, beta, 3000, blood);
  net.outlets.push_back(resistance_outlet(0, 1e15, 2000));
  std::vector<TubeLaw> laws(1);
  laws[0].beta = beta;
  laws[0].reference_area = area;
  laws[0].reference_pressure = 3000;
  laws[0].density = blood.density;
  const ViscosityTable mu(blood);
  LumpedVessels lumped(net, laws, mu, blood, {true});
  lumped.start({3500, 2500}, {0.0});
  const double k = friction_coefficient(blood.alpha);
  auto slope = [&](double p, double q) {
    const double a = laws[0].area(p);
    return -k * mu(a) * q / (a * a);
  };
  auto integrate = [&](double q, double x_end) {
    double p = 3500;
    const int n = 2000;
    const double h = x_end * length / n;
    for (int i = 0; i < n; ++i) {
      const double k1 = slope(p, q), k2 = slope(p + h / 2 * k1, q), k3 = slope(p + h / 2 * k2, q), k4 = slope(p + h * k3, q);
      p += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    }
    return p;
  };
  // The flow that takes the profile from 3500 to 2500 Pa over the vessel (bisection).
  double low = 0, high = 1e-17;
  while (integrate(high, 1) > 2500) high *= 2;
  for (int it = 0; it < 100; ++it) ((integrate(0.5 * (low + high), 1) > 2500) ? low : high) = 0.5 * (low + high);
  const double q = 0.5 * (low + high);
  for (const double x : {0.25, 0.5, 0.75}) {
    const double exact = integrate(q, x), lumped_p = lumped.pressure_at(0, x), line = 3500 - 1000 * x;
    std::printf("capillary at x = %.2f: steady profile %.3f Pa, 0D %.3f Pa, a line %.3f Pa\n", x, exact, lumped_p, line);
    // G = A^2 / (k mu) taken linear in p: a tenth of the profile's departure from a line.
    EXPECT_NEAR(lumped_p, exact, 0.1 * std::abs(exact - line));
  }
}
