// The Riemann problems of the 1D model (physics/riemann.hpp) on their own: the upwind flux
// between elements, the prescribed inflow, the resistance and reflection outlets and the
// junctions, each against the equations it claims to solve, on many random states.
#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "physics/riemann.hpp"
#include "physics/tube_law.hpp"

using namespace hemotree;

namespace {

// Portable uniform numbers: std::mt19937_64's sequence is fixed by the standard, the
// distributions are not.
class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}
  double uniform(double lo, double hi) {
    const double u = static_cast<double>(engine_() >> 11) * 0x1p-53;  // [0, 1)
    return lo + (hi - lo) * u;
  }
  int sign() { return (engine_() >> 63) != 0 ? 1 : -1; }

 private:
  std::mt19937_64 engine_;
};

TubeLaw make_law(double beta, double reference_area, double reference_pressure,
                   double alpha = 4.0 / 3.0, double density = 1050.0) {
  TubeLaw law;
  law.beta = beta;
  law.reference_area = reference_area;
  law.reference_pressure = reference_pressure;
  law.density = density;
  law.alpha = alpha;
  return law;
}

// A random vessel from capillaries to the aorta: wave speeds of about 1 to 15 m/s.
TubeLaw random_law(Random& r) {
  const double diameter = std::exp(r.uniform(std::log(10e-6), std::log(3e-2)));
  const double area = 3.14159265358979323846 / 4 * diameter * diameter;
  const double c = r.uniform(1.0, 15.0);
  const double density = 1050.0;
  const double beta = 2 * density * c * c / std::sqrt(area);  // c^2 = beta sqrt(A) / (2 rho)
  const double alpha = r.uniform(0.0, 1.0) < 0.5 ? 4.0 / 3.0 : 1.1;
  return make_law(beta, area, r.uniform(0.0, 15000.0), alpha, density);
}

// A subsonic trace of the law: area within +-30 % of A_ref, |u| below c / 4.
void random_trace(Random& r, const TubeLaw& law, double& a, double& q) {
  a = law.reference_area * r.uniform(0.7, 1.3);
  q = a * law.wave_speed(a) * r.uniform(-0.25, 0.25);
}

double relative(double x, double y) { return std::abs(x - y) / std::max(std::abs(x), std::abs(y)); }

}  // namespace

// ---- the upwind flux between elements -----------------------------------------------------

TEST(UpwindFlux, IsConsistentWithThePhysicalFlux) {
  Random r(1);
  for (int trial = 0; trial < 1000; ++trial) {
    const TubeLaw law = random_law(r);
    double a, q;
    random_trace(r, law, a, q);
    double fa, fq;
    upwind_flux(law, a, q, a, q, fa, fq);
    EXPECT_EQ(fa, q);
    EXPECT_NEAR(fq, law.flux_flow(a, q), 1e-14 * std::abs(law.flux_flow(a, q)));
  }
}

// For a small jump that is a single wave, the flux is the upwind side's: F(U_l) for a wave
// of the forward family (it comes from the left), F(U_r) for the backward family, up to the
// square of the jump. This pins down the sign of the dissipation |H| (U_r - U_l).
TEST(UpwindFlux, TakesTheUpwindSideOfAWave) {
  Random r(2);
  for (int trial = 0; trial < 200; ++trial) {
    const TubeLaw law = random_law(r);
    double a, q;
    random_trace(r, law, a, q);
    const double lf = law.lambda_forward(a, q), lb = law.lambda_backward(a, q);
    ASSERT_GT(lf, 0);
    ASSERT_LT(lb, 0);
    // Right eigenvectors of H: (1, lambda).
    const double eps = 1e-6 * a;
    const double scale_a = std::abs(lf) * eps, scale_q = std::abs(law.flux_flow(a, q) - law.flux_flow(a + eps, q));
    {
      // Forward wave: U_l = U + eps (1, lf), U_r = U.
      double fa, fq;
      upwind_flux(law, a + eps, q + eps * lf, a, q, fa, fq);
      EXPECT_NEAR(fa, q + eps * lf, 1e-4 * scale_a);
      EXPECT_NEAR(fq, law.flux_flow(a + eps, q + eps * lf), 1e-4 * scale_q);
    }
    {
      // Backward wave: U_l = U, U_r = U + eps (1, lb).
      double fa, fq;
      upwind_flux(law, a, q, a + eps, q + eps * lb, fa, fq);
      EXPECT_NEAR(fa, q + eps * lb, 1e-4 * scale_a);
      EXPECT_NEAR(fq, law.flux_flow(a + eps, q + eps * lb), 1e-4 * scale_q);
    }
  }
}

// ---- the inlet -----------------------------------------------------------------------------

TEST(InflowState, PrescribesTheFlowAndKeepsTheOutgoingCharacteristic) {
  Random r(3);
  for (int trial = 0; trial < 1000; ++trial) {
    const TubeLaw law = random_law(r);
    double a, q;
    random_trace(r, law, a, q);
    const double q_in = a * law.wave_speed(a) * r.uniform(-0.25, 0.25);
    const EndState u = inflow_state(law, a, q, q_in);
    EXPECT_EQ(u.flow, q_in);
    EXPECT_GT(u.area, 0);
    // The backward characteristic leaves through the inlet: l = (-lambda_forward, 1) at the
    // trace, l . (U* - U) = 0.
    const double lf = law.lambda_forward(a, q);
    EXPECT_NEAR(u.flow - q, lf * (u.area - a), 1e-12 * (std::abs(q) + std::abs(q_in) + lf * a));
  }
}

// ---- the outlets -----------------------------------------------------------------------------

TEST(ResistanceState, SolvesTheOutletLawAndKeepsTheOutgoingCharacteristic) {
  Random r(4);
  for (int trial = 0; trial < 1000; ++trial) {
    const TubeLaw law = random_law(r);
    double a, q;
    random_trace(r, law, a, q);
    // Resistances from 0 (an open end at p_beyond) to 100 times the characteristic impedance.
    const double z0 = law.density * law.wave_speed(a) / a;
    const double resistance = trial % 10 == 0 ? 0.0 : z0 * std::exp(r.uniform(std::log(1e-3), std::log(1e2)));
    const double p_beyond = law.pressure(a) - resistance * q + r.uniform(-0.05, 0.05) * law.beta * std::sqrt(a);
    const EndState u = resistance_state(law, a, q, resistance, p_beyond);
    ASSERT_GT(u.area, 0);
    const double p = law.pressure(u.area);
    EXPECT_NEAR(p - resistance * u.flow, p_beyond,
                1e-10 * (std::abs(p) + std::abs(resistance * u.flow) + std::abs(p_beyond)))
        << "trial " << trial << " R " << resistance;
    // The forward characteristic leaves the vessel: Q* - q = lambda_backward (A* - a).
    const double lb = law.lambda_backward(a, q);
    EXPECT_NEAR(u.flow - q, lb * (u.area - a), 1e-12 * (std::abs(q) + std::abs(lb) * a));
  }
}

TEST(ResistanceState, ZeroResistanceFixesThePressure) {
  const TubeLaw law = make_law(4.5e6, 3.14e-4, 1e4);
  const EndState u = resistance_state(law, 3.2e-4, 1e-5, 0.0, 1.2e4);
  EXPECT_NEAR(law.pressure(u.area), 1.2e4, 1e-9);
}

TEST(ReflectionState, NonReflectingOutletHasNoIncomingWave) {
  Random r(5);
  for (int trial = 0; trial < 1000; ++trial) {
    const TubeLaw law = random_law(r);
    double a0, q0, a, q;
    random_trace(r, law, a0, q0);  // the rest state
    random_trace(r, law, a, q);    // the trace
    const EndState u = reflection_state(law, a, q, a0, q0, 0.0);
    // The incoming (backward) linear characteristic measured from rest, with its left
    // eigenvector (-lambda_forward(U0), 1), is zero...
    const double lf0 = law.lambda_forward(a0, q0);
    const double scale = std::abs(q) + std::abs(q0) + lf0 * (a + a0);
    EXPECT_NEAR(-lf0 * (u.area - a0) + (u.flow - q0), 0.0, 1e-12 * scale);
    // ...and the outgoing one keeps the trace: Q* - q = lambda_backward(U) (A* - a).
    const double lb = law.lambda_backward(a, q);
    EXPECT_NEAR(u.flow - q, lb * (u.area - a), 1e-12 * scale);
  }
}

// The coefficient reflects the area (pressure) perturbation of a small outgoing wave: the end
// sees the incident and the reflected wave, (1 + rt) times the incident's. rt = 1 closes the
// end (no flow at rest), rt = -1 opens it (the rest pressure).
TEST(ReflectionState, CoefficientReflectsThePressureWave) {
  const TubeLaw law = make_law(4.5e6, 3.14e-4, 1e4);
  const double a0 = 3.3e-4, q0 = 0;  // at rest
  const double lf = law.lambda_forward(a0, q0);
  for (double rt : {-1.0, -0.5, 0.0, 0.3, 1.0}) {
    const double eps = 1e-7 * a0;  // an outgoing (forward) wave of area amplitude eps
    const EndState u = reflection_state(law, a0 + eps, q0 + lf * eps, a0, q0, rt);
    EXPECT_NEAR((u.area - a0) / eps, 1 + rt, 1e-6) << "rt " << rt;
    // The reflected wave carries -rt times the flow: (1 - rt) of the incident flow.
    EXPECT_NEAR((u.flow - q0) / (lf * eps), 1 - rt, 1e-6) << "rt " << rt;
  }
  // Closed end at rest: no flow whatever the trace.
  EXPECT_EQ(reflection_state(law, 3.5e-4, 2e-4, a0, 0.0, 1.0).flow, 0.0);
  // Open end: the rest area.
  EXPECT_NEAR(reflection_state(law, 3.5e-4, 2e-4, a0, 0.0, -1.0).area, a0, 1e-15 * a0);
}

// ---- junctions -------------------------------------------------------------------------------

namespace {

struct JunctionCase {
  std::vector<TubeLaw> laws;
  std::vector<const TubeLaw*> law_ptr;
  std::vector<double> a, q;
  std::vector<int> sign;
  std::vector<EndState> out;
};

// n ends of comparable vessels (diameters within a factor 0.6..1 of a common size and wave
// speeds within 4..8 m/s, as at a branching point) near a common pressure, with flows of up
// to a tenth of the wave speed; at least one end on each side. (Ends of very different wave
// speeds with large opposite flows can choke: no subsonic state carries the mass, and
// junction_state rightly reports failure.)
JunctionCase random_junction(Random& r, std::size_t n) {
  JunctionCase c;
  c.laws.resize(n);
  c.a.resize(n);
  c.q.resize(n);
  c.sign.resize(n);
  c.out.resize(n);
  const double size = std::exp(r.uniform(std::log(10e-6), std::log(3e-2)));
  const double pressure = r.uniform(5e3, 15e3);
  for (std::size_t i = 0; i < n; ++i) {
    const double diameter = size * r.uniform(0.6, 1.0);
    const double area = 3.14159265358979323846 / 4 * diameter * diameter;
    const double wave_speed = r.uniform(4.0, 8.0);
    const double beta = 2 * 1050.0 * wave_speed * wave_speed / std::sqrt(area);
    c.laws[i] = make_law(beta, area, pressure + r.uniform(-2e3, 2e3), r.uniform(0, 1) < 0.5 ? 4.0 / 3.0 : 1.1);
    const TubeLaw& law = c.laws[i];
    // A trace near the law's area at the common pressure, +-10 % in area.
    c.a[i] = law.area(pressure) * r.uniform(0.9, 1.1);
    c.q[i] = c.a[i] * law.wave_speed(c.a[i]) * r.uniform(-0.1, 0.1);
    c.sign[i] = i == 0 ? 1 : (i == 1 ? -1 : r.sign());
  }
  for (const auto& law : c.laws) c.law_ptr.push_back(&law);
  return c;
}

}  // namespace

TEST(JunctionState, ConservesMassAndTotalPressureOnRandomStates) {
  Random r(6);
  int solved = 0;
  for (std::size_t n : {2u, 3u, 4u, 6u, 17u, 24u}) {  // beyond 16 ends: the heap's scratch
    for (int trial = 0; trial < 300; ++trial) {
      JunctionCase c = random_junction(r, n);
      const bool ok = junction_state(c.law_ptr, c.a, c.q, c.sign, c.out);
      ASSERT_TRUE(ok) << "n " << n << " trial " << trial;
      ++solved;
      double mass = 0, flow_scale = 0;
      for (std::size_t i = 0; i < n; ++i) {
        mass += c.sign[i] * c.out[i].flow;
        // Q* = q + mu (A* - a) rounds at the size of its terms.
        const double mu = std::abs(incoming_speed(c.laws[i], c.a[i], c.q[i], c.sign[i] > 0));
        flow_scale += std::abs(c.out[i].flow) + std::abs(c.q[i]) + mu * c.a[i];
        EXPECT_GT(c.out[i].area, 0);
      }
      EXPECT_LE(std::abs(mass), 1e-12 * flow_scale) << "n " << n << " trial " << trial;
      const double pt0 = c.laws[0].total_pressure(c.out[0].area, c.out[0].flow);
      for (std::size_t i = 1; i < n; ++i)
        EXPECT_LE(relative(c.laws[i].total_pressure(c.out[i].area, c.out[i].flow), pt0), 1e-10)
            << "n " << n << " trial " << trial << " end " << i;
      // Each end keeps the characteristic that leaves its vessel into the node.
      for (std::size_t i = 0; i < n; ++i) {
        const double mu = incoming_speed(c.laws[i], c.a[i], c.q[i], c.sign[i] > 0);
        EXPECT_NEAR(c.out[i].flow - c.q[i], mu * (c.out[i].area - c.a[i]),
                    1e-12 * (std::abs(c.q[i]) + std::abs(mu) * c.a[i]));
      }
    }
  }
  EXPECT_EQ(solved, 1800);
}

TEST(JunctionState, RefusesFewerThanTwoEnds) {
  const TubeLaw law = make_law(4.5e6, 3.14e-4, 1e4);
  const TubeLaw* laws[] = {&law};
  const double a[] = {3.3e-4}, q[] = {2e-5};
  const int sign[] = {1};
  std::array<EndState, 1> out;
  EXPECT_FALSE(junction_state(laws, a, q, sign, out));
}

// Two ends of the same vessel with a continuous state: the junction changes nothing.
TEST(JunctionState, ContinuousStateThroughTwoEqualVesselsIsUnchanged) {
  const TubeLaw law = make_law(4.5e6, 3.14e-4, 1e4);
  const TubeLaw* laws[] = {&law, &law};
  const double a[] = {3.3e-4, 3.3e-4}, q[] = {2e-5, 2e-5};
  const int sign[] = {1, -1};
  std::array<EndState, 2> out;
  ASSERT_TRUE(junction_state(laws, a, q, sign, out));
  for (const EndState& u : out) {
    EXPECT_NEAR(u.area, 3.3e-4, 1e-14 * 3.3e-4);
    EXPECT_NEAR(u.flow, 2e-5, 1e-13 * 2e-5);
  }
}
