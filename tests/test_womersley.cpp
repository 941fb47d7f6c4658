// Womersley waves (the paper's eq. wavespeedWomersley; ERRATA.md s. 5): Bessel functions of
// real and complex argument, the Womersley number, and the limits of the phase velocity.
// Reference values not from the standard library were computed with mpmath (30 digits).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <stdexcept>

#include "core/errors.hpp"
#include "physics/womersley.hpp"

using namespace hemotree;

namespace {

using Complex = std::complex<double>;

// i^(3/2) x = x e^(3 i pi / 4).
Complex i32(double x) { return std::polar(x, 0.75 * std::numbers::pi); }

void expect_complex_near(Complex actual, Complex expected, double tolerance) {
  EXPECT_NEAR(actual.real(), expected.real(), tolerance) << "argument value " << expected;
  EXPECT_NEAR(actual.imag(), expected.imag(), tolerance) << "argument value " << expected;
}

TEST(Bessel, RealArgumentsMatchTheStandardLibrary) {
  for (double x : {0.1, 1.0, 5.0, 10.0}) {
    for (int n : {0, 1}) {
      const Complex j = bessel_j(n, Complex(x, 0));
      EXPECT_NEAR(j.real(), std::cyl_bessel_j(n, x), 1e-13) << "n = " << n << ", x = " << x;
      EXPECT_EQ(j.imag(), 0.0);
    }
  }
  EXPECT_EQ(bessel_j(0, 0.0), Complex(1, 0));
  EXPECT_EQ(bessel_j(1, 0.0), Complex(0, 0));
}

TEST(Bessel, HankelBranchMatchesReferenceBeyondTheSeries) {
  // |z| > 20: the asymptotic expansion, on both signs of Re z.
  EXPECT_NEAR(bessel_j(0, 25.0).real(), std::cyl_bessel_j(0, 25.0), 1e-14);
  EXPECT_NEAR(bessel_j(1, 25.0).real(), std::cyl_bessel_j(1, 25.0), 1e-14);
  EXPECT_NEAR(bessel_j(0, -30.0).real(), -0.0863679835810402113, 1e-14);
  EXPECT_NEAR(bessel_j(1, -30.0).real(), 0.1187510626166229365, 1e-14);
  // Complex: relative to |J|, from mpmath.
  const Complex j0_25(9797.71694973549028, -3808789.91144403569);
  const Complex j1_25(3754808.47314300781, 64306.8143930464548);
  EXPECT_LT(std::abs(bessel_j(0, i32(25)) - j0_25), 1e-13 * std::abs(j0_25));
  EXPECT_LT(std::abs(bessel_j(1, i32(25)) - j1_25), 1e-13 * std::abs(j1_25));
}

TEST(Bessel, SeriesAndHankelAgreeAtTheSwitch) {
  // |z| = 20 -+ 1e-13: J itself changes by ~2e-13 relative across the step.
  for (double angle : {0.0, 0.5, 0.75 * std::numbers::pi, 2.5}) {
    for (int n : {0, 1}) {
      const Complex below = bessel_j(n, std::polar(20.0 - 1e-13, angle));
      const Complex above = bessel_j(n, std::polar(20.0 + 1e-13, angle));
      EXPECT_LT(std::abs(below - above), 1e-12 * std::max(1.0, std::abs(below)))
          << "n = " << n << ", arg z = " << angle;
    }
  }
}

TEST(Bessel, KelvinFunctions) {
  // J0(i^(3/2) x) = ber(x) + i bei(x). Values of ber, bei (A&S table 9.12; checked with mpmath).
  // The brief's ber(5) = -6.23008499, bei(5) = 0.11603130 disagree with both this series and
  // mpmath by ~3e-6; mpmath gives ber(5) = -6.2300824787, bei(5) = 0.1160343816.
  expect_complex_near(bessel_j(0, i32(1)), {0.98438178, 0.24956604}, 1e-7);
  expect_complex_near(bessel_j(0, i32(2)), {0.75173418, 0.97229163}, 1e-7);
  expect_complex_near(bessel_j(0, i32(5)), {-6.23008248, 0.11603438}, 1e-7);
  expect_complex_near(bessel_j(0, i32(10)), {138.84046594, 56.37045855}, 1e-7);
}

TEST(Bessel, RefusesOtherOrdersAndNonFiniteArguments) {
  EXPECT_THROW(bessel_j(2, 1.0), std::domain_error);
  EXPECT_THROW(bessel_j(-1, 1.0), std::domain_error);
  EXPECT_THROW(bessel_j(0, Complex(NAN, 0)), std::domain_error);
  EXPECT_THROW(bessel_j(0, Complex(0, INFINITY)), std::domain_error);
  EXPECT_THROW(bessel_j(0, Complex(0, 800)), std::domain_error);  // overflows double
}

TEST(WomersleyNumber, ByHand) {
  // D = 4 mm, rho = 1000 kg/m^3, mu = 1 mPa s, omega = 4 rad/s: sqrt(4e6) = 2000, W = 0.002 * 2000.
  EXPECT_NEAR(womersley_number(4e-3, 1000, 1e-3, 4), 4.0, 1e-14);
  // D = 20 mm, rho = 1000, mu = 4 mPa s, omega = 10: W = 0.01 sqrt(2.5e6) = 15.8113883...
  EXPECT_NEAR(womersley_number(0.02, 1000, 4e-3, 10), 15.811388300841896, 1e-12);
  EXPECT_THROW(womersley_number(0, 1000, 1e-3, 4), InputError);
  EXPECT_THROW(womersley_number(1e-3, 1000, -1e-3, 4), InputError);
  EXPECT_THROW(womersley_number(1e-3, NAN, 1e-3, 4), InputError);
}

TEST(WomersleyWave, MatchesReferenceValues) {
  const double c0 = 5.0, omega = 2 * std::numbers::pi * 1.2;
  const WomersleyWave wave = womersley_wave(c0, 1.5, omega);
  EXPECT_NEAR(wave.phase_velocity / c0, 0.62356197128661816, 1e-12);
  EXPECT_NEAR(wave.attenuation, 4.3622375911633944, 1e-11);
  EXPECT_GT(wave.wave_number.real(), 0);
  EXPECT_NEAR(wave.phase_velocity, omega / wave.wave_number.real(), 1e-12);
  EXPECT_NEAR(womersley_wave(c0, 20, omega).phase_velocity / c0, 0.96592698223470821, 1e-12);
  EXPECT_NEAR(womersley_wave(c0, 20, omega).attenuation, 0.23021778784242769, 1e-11);
  EXPECT_NEAR(womersley_wave(c0, 1000, omega).phase_velocity / c0, 0.99929339348385331, 1e-12);
}

TEST(WomersleyWave, LargeWomersleyTendsToTheElasticSpeed) {
  const double c0 = 3.0, omega = 10.0;
  EXPECT_NEAR(womersley_wave(c0, 20, omega).phase_velocity / c0, 1.0, 0.10);
  EXPECT_NEAR(womersley_wave(c0, 15, omega).phase_velocity / c0, 1.0, 0.05);
  EXPECT_NEAR(womersley_wave(c0, 1e4, omega).phase_velocity / c0, 1.0, 1e-3);
  // Monotone increase of c with W, never above c0, from the small-W branch through the
  // series and the asymptotic ranges.
  double previous = 0;
  for (double w = 1e-4; w < 2e3; w *= 1.05) {
    const double c = womersley_wave(c0, w, omega).phase_velocity;
    EXPECT_GT(c, previous) << "W = " << w;
    EXPECT_LT(c, c0) << "W = " << w;
    previous = c;
  }
}

TEST(WomersleyWave, SmallWomersleyTendsToHalfWTimesTheElasticSpeed) {
  // c -> W c0 / 2 (ERRATA.md s. 5): the ratio c / (W c0 / 2) tends to 1, not sqrt 2
  // (1 - F10 ~ i W^2 / 8, k ~ (omega / c0)(2 / W)(1 - i)), and gamma -> 2 pi.
  const double c0 = 4.0, omega = 20.0;
  for (double w : {0.1, 0.01, 1e-3, 1e-4}) {
    const WomersleyWave wave = womersley_wave(c0, w, omega);
    EXPECT_NEAR(wave.phase_velocity / (w * c0 / 2), 1.0, 0.01) << "W = " << w;
    EXPECT_NEAR(wave.attenuation, 2 * std::numbers::pi, 0.01 * 2 * std::numbers::pi);
  }
  // mpmath (40 digits) at W = 0.01: c / c0 = 0.0049999583334852452, gamma = 6.2830805882971325.
  EXPECT_NEAR(womersley_wave(c0, 0.01, omega).phase_velocity / c0, 0.0049999583334852452, 1e-16);
  EXPECT_NEAR(womersley_wave(c0, 0.01, omega).attenuation, 6.2830805882971325, 1e-12);
  // The analytic branch below W = 1e-3 joins the series continuously.
  const double below = womersley_wave(c0, 1e-3 * (1 - 1e-12), omega).phase_velocity;
  const double above = womersley_wave(c0, 1e-3, omega).phase_velocity;
  EXPECT_NEAR(below / above, 1.0, 1e-11);
}

TEST(WomersleyWave, RejectsNonPositiveInputs) {
  EXPECT_THROW(womersley_wave(0, 1, 1), InputError);
  EXPECT_THROW(womersley_wave(1, 0, 1), InputError);
  EXPECT_THROW(womersley_wave(1, 1, -1), InputError);
  EXPECT_THROW(womersley_wave(1, INFINITY, 1), InputError);
}

}  // namespace
