// The extremes of an oscillation given by its harmonics (harmonic/trigonometric_extremes.hpp)
// against closed forms and against dense sampling.
#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "harmonic/trigonometric_extremes.hpp"

namespace hemotree {
namespace {

using C = std::complex<double>;

double value(const std::vector<C>& c, double theta) {
  double f = 0;
  for (std::size_t j = 0; j < c.size(); ++j) f += (c[j] * std::polar(1.0, static_cast<double>(j + 1) * theta)).real();
  return f;
}

TEST(TrigonometricExtremes, OneHarmonicSwingsByItsModulus) {
  const TrigonometricExtremes extremes(1);
  std::vector<double> scratch;
  const std::vector<C> c{std::polar(3.5, 0.7)};
  const Extremes e = extremes(c, scratch);
  EXPECT_NEAR(e.greatest, 3.5, 1e-14);
  EXPECT_NEAR(e.least, -3.5, 1e-14);
}

TEST(TrigonometricExtremes, TwoHarmonicsHaveTheirClosedForm) {
  // cos t + cos(2t) / 2: greatest 3/2 at t = 0, least -3/4 where cos t = -1/2, between the
  // samples (t = 2 pi / 3 is no multiple of 2 pi / 16).
  const TrigonometricExtremes extremes(2);
  std::vector<double> scratch;
  const std::vector<C> c{1.0, 0.5};
  const Extremes e = extremes(c, scratch);
  EXPECT_NEAR(e.greatest, 1.5, 1e-14);
  EXPECT_NEAR(e.least, -0.75, 1e-14);
}

TEST(TrigonometricExtremes, AreThoseOfDenseSamplingWithinItsError) {
  // Random series, with amplitudes decaying as a pulse's do and flat: the result is never
  // short of 2^16 samples' extremes (less rounding) and beyond them by at most what those
  // samples can miss, S h^2 / 8 with S = sum k^2 |c_k|.
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (const int harmonics : {3, 10, 25, 80}) {  // 80: beyond 64, 4 K samples
    const TrigonometricExtremes extremes(harmonics);
    std::vector<double> scratch;
    for (int trial = 0; trial < (harmonics > 64 ? 6 : 40); ++trial) {
      std::vector<C> c(static_cast<std::size_t>(harmonics));
      double s = 0, scale = 0;
      for (std::size_t j = 0; j < c.size(); ++j) {
        const double decay = trial % 2 ? 1.0 : 1.0 / static_cast<double>((j + 1) * (j + 1));
        c[j] = decay * C(unit(random), unit(random));
        s += static_cast<double>((j + 1) * (j + 1)) * std::abs(c[j]);
        scale += std::abs(c[j]);
      }
      const int dense = 1 << 16;
      double high = -1e300, low = 1e300;
      for (int m = 0; m < dense; ++m) {
        const double f = value(c, 2 * std::numbers::pi * m / dense);
        high = std::max(high, f), low = std::min(low, f);
      }
      const double h = 2 * std::numbers::pi / dense, missed = s * h * h / 8, rounding = 1e-13 * scale;
      const Extremes e = extremes(c, scratch);
      EXPECT_GE(e.greatest, high - rounding) << harmonics << " harmonics, trial " << trial;
      EXPECT_LE(e.greatest, high + missed + rounding) << harmonics << " harmonics, trial " << trial;
      EXPECT_LE(e.least, low + rounding) << harmonics << " harmonics, trial " << trial;
      EXPECT_GE(e.least, low - missed - rounding) << harmonics << " harmonics, trial " << trial;
    }
  }
}

TEST(TrigonometricExtremes, AFlatSeriesIsZero) {
  const TrigonometricExtremes extremes(4);
  std::vector<double> scratch;
  const Extremes e = extremes(std::vector<C>(4, 0.0), scratch);
  EXPECT_EQ(e.greatest, 0.0);
  EXPECT_EQ(e.least, 0.0);
}

}  // namespace
}  // namespace hemotree
