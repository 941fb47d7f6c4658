// The tube law (physics/tube_law.hpp): each quantity it gives against its definition from
// p(A) alone, so that a new law modelled on it can be held to the same checks: the inverse
// A(p) by the round trip, dA/dp, dp/dA and c^2 = (A / rho) dp/dA by central differences of
// p(A) or A(p), the flux's pressure part as the integral of c^2, the characteristic speeds at
// rest, and the forms in sqrt(A) that the junctions and the 0D vessels use.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "physics/tube_law.hpp"
#include "physics/vessel_taper.hpp"
#include "physics/wall_law.hpp"

using namespace hemotree;

namespace {

constexpr double um = 1e-6;
constexpr double mmHg = 133.322;
constexpr double rho = 1050;

static_assert(TubeLawInterface<TubeLaw>);

// A law that gives p(A) and nothing else is not a tube law: the solvers need the rest.
struct PressureOnly {
  double pressure(double a) const { return a; }
};
static_assert(!TubeLawInterface<PressureOnly>);

void expect_relative(double actual, double expected, double tolerance) {
  EXPECT_NEAR(actual, expected, tolerance * std::abs(expected)) << "relative error " << (actual - expected) / expected;
}

TubeLaw with_blood(TubeLaw law) {
  law.density = rho;
  law.alpha = 4.0 / 3.0;
  return law;
}

// A capillary (thin wall), an arteriole (thick wall, Table 1), and an artery whose beta is
// given (c = 5 m/s at A_ref, p_ref = 80 mmHg).
std::vector<TubeLaw> sample_laws() {
  TubeLaw artery;
  artery.reference_area = std::numbers::pi / 4 * 4e-3 * 4e-3;
  artery.beta = 2 * rho * 5.0 * 5.0 / std::sqrt(artery.reference_area);
  artery.reference_pressure = 80 * mmHg;
  return {with_blood(thin_wall_tube_law({6 * um, 0.6 * um, 160e3}, 10 * mmHg)),
          with_blood(thick_wall_tube_law({20 * um, 6.5 * um, 630e3}, 10 * mmHg)), with_blood(artery)};
}

// Lumens from half to twice the reference.
const std::vector<double> area_factors = {0.5, 0.8, 1.0, 1.3, 2.0};

}  // namespace

TEST(TubeLaw, AreaOfPressureIsTheInverse) {
  for (const TubeLaw& law : sample_laws()) {
    const double scale = law.beta * std::sqrt(law.reference_area);  // the law's pressure scale
    for (const double s : area_factors) {
      const double p = law.pressure(s * law.reference_area);
      EXPECT_NEAR(law.pressure(law.area(p)), p, 1e-12 * scale);
      expect_relative(law.area(p), s * law.reference_area, 1e-12);
    }
    EXPECT_EQ(law.pressure(law.reference_area), law.reference_pressure);
  }
}

TEST(TubeLaw, ComplianceIsDAreaDPressure) {
  for (const TubeLaw& law : sample_laws()) {
    for (const double s : area_factors) {
      const double a = s * law.reference_area, p = law.pressure(a);
      const double dp = 1e-4 * law.beta * std::sqrt(a);  // moves the radius by about 1e-4
      const double numerical = (law.area(p + dp) - law.area(p - dp)) / (2 * dp);
      expect_relative(law.compliance_per_length(a), numerical, 1e-8);
      // Its inverse, and a vessel's: C = L dA/dp.
      expect_relative(law.pressure_slope(a), 1 / law.compliance_per_length(a), 1e-14);
      expect_relative(law.compliance(0.01, a), 0.01 * law.compliance_per_length(a), 1e-14);
    }
  }
}

TEST(TubeLaw, WaveSpeedIsTheSlopeOfPressure) {
  for (const TubeLaw& law : sample_laws()) {
    for (const double s : area_factors) {
      const double a = s * law.reference_area, da = 1e-5 * a;
      const double dp_da = (law.pressure(a + da) - law.pressure(a - da)) / (2 * da);
      expect_relative(law.pressure_slope(a), dp_da, 1e-7);
      const double c = law.wave_speed(a);
      expect_relative(c * c, a / rho * dp_da, 1e-7);
    }
  }
}

// The pressure part of the momentum flux is int_0^A (a / rho) dp/da da: its derivative in A
// is c^2, and it vanishes with A.
TEST(TubeLaw, FluxPressurePartIsTheIntegralOfWaveSpeedSquared) {
  for (const TubeLaw& law : sample_laws()) {
    auto pressure_part = [&](double a) { return law.flux_flow(a, 0.0); };
    for (const double s : area_factors) {
      const double a = s * law.reference_area, da = 1e-5 * a;
      const double c = law.wave_speed(a);
      expect_relative((pressure_part(a + da) - pressure_part(a - da)) / (2 * da), c * c, 1e-8);
      // The block form the DG volume term uses is the same quantity.
      expect_relative(TubeLaw::pressure_flux(law.beta / (3 * rho), a), pressure_part(a), 1e-14);
      // The convective part alpha Q^2 / A, and F_A = Q.
      const double q = 0.3 * c * a;
      expect_relative(law.flux_flow(a, q) - pressure_part(a), law.alpha * q * q / a, 1e-9);
      EXPECT_EQ(law.flux_area(a, q), q);
    }
  }
}

TEST(TubeLaw, CharacteristicSpeedsAtRestArePlusMinusWaveSpeed) {
  for (const TubeLaw& law : sample_laws()) {
    for (const double s : area_factors) {
      const double a = s * law.reference_area, c = law.wave_speed(a);
      expect_relative(law.lambda_forward(a, 0.0), c, 1e-14);
      expect_relative(law.lambda_backward(a, 0.0), -c, 1e-14);
      // With flow they are the eigenvalues of the flux Jacobian [[0, 1], [c^2 - alpha u^2, 2 alpha u]]:
      // their sum is its trace, their product its determinant.
      const double u = 0.2 * c, q = u * a;
      const double l1 = law.lambda_forward(a, q), l2 = law.lambda_backward(a, q);
      expect_relative(l1 + l2, 2 * law.alpha * u, 1e-12);
      expect_relative(l1 * l2, -(c * c - law.alpha * u * u), 1e-12);
    }
  }
}

TEST(TubeLaw, TotalPressureAddsTheKineticPart) {
  for (const TubeLaw& law : sample_laws()) {
    const double a = law.reference_area, u = 0.5;
    EXPECT_EQ(law.total_pressure(a, 0.0), law.pressure(a));
    expect_relative(law.total_pressure(a, u * a) - law.pressure(a), 0.5 * rho * u * u, 1e-9);
  }
}

// The law is linear in sqrt(A): the junction's form and the 0D vessels' c + d p are it.
TEST(TubeLaw, FormsInTheRootOfTheLumen) {
  for (const TubeLaw& law : sample_laws()) {
    const double root_reference = std::sqrt(law.reference_area);
    for (const double s : area_factors) {
      const double a = s * law.reference_area, root = std::sqrt(a), p = law.pressure(a);
      EXPECT_EQ(law.pressure_of_root(root, root_reference), p);
      EXPECT_EQ(law.pressure_slope_of_root(root), law.pressure_slope(a));
      expect_relative(law.lumen_root(p), root, 1e-12);
      expect_relative(law.lumen_root_intercept() + law.lumen_root_slope() * p, root, 1e-12);
    }
    // Below the collapse pressure, where sqrt(A) would be negative, the lumen is shut.
    const double collapse = law.pressure_of_root(0, root_reference);
    EXPECT_LT(law.lumen_root(collapse - 1.0), 0.0);
    EXPECT_EQ(law.area(collapse - 1.0), 0.0);
  }
}

// A tapered vessel gives the one law at each point, with its blood.
TEST(TubeLaw, TaperGivesTheLawAlongTheVessel) {
  VesselTaper taper;
  taper.d0 = 40 * um;
  taper.d1 = 20 * um;
  taper.length = 1e-3;
  taper.density = rho;
  taper.wall = {40 * um, 4 * um, 400e3};
  taper.model = WallModel::thin;
  taper.external_pressure = 10 * mmHg;
  for (const double s : {0.0, 0.5, 1.0}) {
    const TubeLaw law = taper.at(s);
    const TubeLaw wall = thin_wall_tube_law({taper.diameter(s), 4 * um, 400e3}, 10 * mmHg);
    EXPECT_EQ(law.beta, wall.beta);
    EXPECT_EQ(law.reference_area, wall.reference_area);
    EXPECT_EQ(law.density, rho);
    // The measured lumen is at p_ext all along: the rest state.
    expect_relative(law.pressure(taper.rest_area(s)), 10 * mmHg, 1e-12);
  }
}
