// The in vivo viscosity law of Pries et al. (1994) with the published exponents (ERRATA.md
// s. 1), the apparent viscosity built on it, and the Poiseuille resistance.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "core/errors.hpp"
#include "physics/blood.hpp"
#include "physics/poiseuille.hpp"
#include "physics/rheology.hpp"

using namespace hemotree;

namespace {

constexpr double um = 1e-6;

void expect_relative(double actual, double expected, double tolerance) {
  EXPECT_NEAR(actual, expected, tolerance * std::abs(expected))
      << "relative error " << (actual - expected) / expected;
}

}  // namespace

// Reference values, computed independently of this code from the published formula with
// Python's mpmath at 50 significant digits (python3, mpmath 1.3.0):
//
//   from mpmath import mp, mpf, exp
//   mp.dps = 50
//   def eta(D, Hd):                     # D in um
//       D, Hd = mpf(D), mpf(Hd)
//       s = 1 / (1 + mpf('1e-11') * D**12)
//       C = (mpf('0.8') + exp(mpf('-0.075') * D)) * (-1 + s) + s
//       e45 = 6*exp(mpf('-0.085')*D) + mpf('3.2') - mpf('2.44')*exp(mpf('-0.06')*D**mpf('0.645'))
//       k = (D / (D - mpf('1.1')))**2
//       return (1 + (e45 - 1) * ((1 - Hd)**C - 1) / ((1 - mpf('0.45'))**C - 1) * k) * k
//
//   D [um]   C            eta045        eta (Hd 0.45)         eta (Hd 0.30)
//     5      0.99394231   5.062900117   12.620000133362362    8.9567159105401346
//    10     -1.0657878    3.892398998    5.8724376741789005   3.6550395820847409
//    20     -1.0230808    2.683743625    3.2310835617244913   2.2221420621557485
//    50     -0.82351775   2.130873244    2.2816097508069689   1.7089414818471347
//   100     -0.80055308   2.44385486     2.5315391248458017   1.8349039597132026
//   300     -0.8          2.973331053    3.0099143678846583   2.0856200886307546
//  1000                                  3.1979224062202887
//  3000                                  3.2038955947075516
TEST(PriesViscosity, MatchesHandComputedTable) {
  struct Row {
    double diameter_um, eta_045, eta_030;
  };
  const std::vector<Row> table = {
      {5, 12.620000133362362, 8.9567159105401346},
      {10, 5.8724376741789005, 3.6550395820847409},
      {20, 3.2310835617244913, 2.2221420621557485},
      {50, 2.2816097508069689, 1.7089414818471347},
      {100, 2.5315391248458017, 1.8349039597132026},
      {300, 3.0099143678846583, 2.0856200886307546},
  };
  for (const Row& row : table) {
    SCOPED_TRACE(row.diameter_um);
    expect_relative(pries_relative_viscosity(row.diameter_um * um, 0.45), row.eta_045, 1e-9);
    expect_relative(pries_relative_viscosity(row.diameter_um * um, 0.30), row.eta_030, 1e-9);
  }
}

// The shape exponent C crosses zero at D = 8.0518294467249548701 um (mpmath findroot), where
// ((1 - Hd)^C - 1) / (0.55^C - 1) is 0/0 with limit ln(1 - Hd) / ln(0.55). Evaluated as
// pow - 1 it loses all its digits there; the law itself is smooth.
//   eta(8.051829446724955, 0.45) = 7.2594269458667199    (C = -4.2e-16 at this double)
//   eta(8.051829446724955, 0.30) = 4.872188862570085
//   eta(8.05, 0.45)              = 7.2611040655017567    (C = 1.5e-3)
TEST(PriesViscosity, AccurateWhereTheShapeExponentVanishes) {
  expect_relative(pries_relative_viscosity(8.051829446724955 * um, 0.45), 7.2594269458667199,
                  1e-9);
  expect_relative(pries_relative_viscosity(8.051829446724955 * um, 0.30), 4.872188862570085,
                  1e-9);
  expect_relative(pries_relative_viscosity(8.05 * um, 0.45), 7.2611040655017567, 1e-9);
}

// Without cells the hematocrit factor vanishes and eta = (D / (D - 1.1))^2: plasma in a lumen
// narrowed by the in vivo wall layer, tending to 1 (plasma) in large vessels.
TEST(PriesViscosity, CellFreeLimitIsTheWallLayerFactor) {
  for (double d : {2.0, 5.0, 10.0, 100.0, 3000.0}) {
    SCOPED_TRACE(d);
    const double k = std::pow(d / (d - 1.1), 2);
    expect_relative(pries_relative_viscosity(d * um, 0.0), k, 1e-14);
  }
  expect_relative(pries_relative_viscosity(10 * um, 0.0), 1.2624668602449186, 1e-14);
  EXPECT_NEAR(pries_relative_viscosity(1 /*m*/, 0.0), 1.0, 1e-5);
}

// At Hd = 0.45 eta tends to eta045(inf) = 3.2 in large vessels, about 3.0 at 300 um.
TEST(PriesViscosity, PlateausNearThreeTwoInLargeVessels) {
  EXPECT_NEAR(pries_relative_viscosity(300 * um, 0.45), 3.0, 0.02);
  expect_relative(pries_relative_viscosity(1000 * um, 0.45), 3.1979224062202887, 1e-9);
  expect_relative(pries_relative_viscosity(3000 * um, 0.45), 3.2038955947075516, 1e-9);
  // D^12 overflows to inf in double beyond about 1e25 um; the switch s = 1/(1 + 1e-11 D^12)
  // then reads 0, its correct limit, and the law stays finite.
  const double huge = pries_relative_viscosity(1e30, 0.45);
  EXPECT_TRUE(std::isfinite(huge));
  EXPECT_NEAR(huge, 3.2, 1e-12);
}

// The paper's printed exponents (D^0.0645, exp(-0.0075 D)) make eta045 fall below 1 above
// about 55 um: blood thinner than its plasma. The published law never does.
TEST(PriesViscosity, BloodIsNeverThinnerThanPlasma) {
  for (double hd : {0.1, 0.3, 0.45, 0.6}) {
    for (double log_d = std::log(3.0); log_d <= std::log(3000.0) + 1e-12;
         log_d += std::log(3000.0 / 3.0) / 400) {
      const double d = std::exp(log_d);
      ASSERT_GT(pries_relative_viscosity(d * um, hd), 1.0) << "D = " << d << " um, Hd " << hd;
    }
  }
}

TEST(PriesViscosity, IncreasesWithHematocrit) {
  for (double d : {3.0, 5.0, 8.05, 10.0, 20.0, 50.0, 100.0, 300.0, 1000.0}) {
    double previous = pries_relative_viscosity(d * um, 0.0);
    for (int i = 1; i <= 19; ++i) {
      const double hd = 0.05 * i;
      const double eta = pries_relative_viscosity(d * um, hd);
      EXPECT_GT(eta, previous) << "D = " << d << " um, Hd " << hd;
      previous = eta;
    }
  }
}

TEST(PriesViscosity, RefusesArgumentsOutsideItsDomain) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(pries_relative_viscosity(1.1 * um, 0.45), InputError);  // k(D) is singular
  EXPECT_THROW(pries_relative_viscosity(0.5 * um, 0.45), InputError);
  EXPECT_THROW(pries_relative_viscosity(-10 * um, 0.45), InputError);
  EXPECT_THROW(pries_relative_viscosity(nan, 0.45), InputError);
  EXPECT_THROW(pries_relative_viscosity(10 * um, -0.01), InputError);
  EXPECT_THROW(pries_relative_viscosity(10 * um, 1.0), InputError);
  EXPECT_THROW(pries_relative_viscosity(10 * um, nan), InputError);
}

TEST(ApparentViscosity, PriesIsPlasmaTimesRelativeViscosity) {
  const Blood blood;  // Pries, Hd 0.45, plasma 1 mPa s
  expect_relative(apparent_viscosity(blood, 10 * um), 1.0e-3 * 5.8724376741789005, 1e-9);
  Blood thin = blood;
  thin.hematocrit = 0.30;
  thin.plasma_viscosity = 1.2e-3;
  expect_relative(apparent_viscosity(thin, 50 * um), 1.2e-3 * 1.7089414818471347, 1e-9);
}

// Above pries_max_diameter the viscosity is frozen at its value there: continuous, constant.
TEST(ApparentViscosity, ContinuousAndConstantAboveThreshold) {
  const Blood blood;
  const double at = apparent_viscosity(blood, blood.pries_max_diameter);
  expect_relative(at, 1.0e-3 * 3.0099143678846583, 1e-9);
  EXPECT_EQ(apparent_viscosity(blood, blood.pries_max_diameter * (1 + 1e-12)), at);
  EXPECT_EQ(apparent_viscosity(blood, 1e-3), at);
  EXPECT_EQ(apparent_viscosity(blood, 2.5e-2), at);
  expect_relative(apparent_viscosity(blood, blood.pries_max_diameter * (1 - 1e-9)), at, 1e-9);
}

// Rat blood (mean cell volume 55 fl against the human 92): the law sees the diameter times
// (92/55)^(1/3) = 1.1870664916, as NetFlow does. eta(11.870664916 um, 0.4) = 4.2781233416901330
// (the script above; eta(10 um, 0.4) = 5.0059805425975064 for human cells): smaller cells pass
// a 10 um capillary 15 % more easily.
TEST(ApparentViscosity, MeanCellVolumeScalesTheDiameterTheLawSees) {
  Blood rat;
  rat.hematocrit = 0.4;
  rat.plasma_viscosity = 1.0466e-3;
  rat.mean_cell_volume = 55e-18;
  expect_relative(rat.pries_diameter_scale(), 1.1870664916411232, 1e-14);
  expect_relative(apparent_viscosity(rat, 10 * um), 1.0466e-3 * 4.2781233416901330, 1e-9);
  Blood human = rat;
  human.mean_cell_volume = Blood::human_mean_cell_volume;
  EXPECT_EQ(human.pries_diameter_scale(), 1.0);
  expect_relative(apparent_viscosity(human, 10 * um), 1.0466e-3 * 5.0059805425975064, 1e-9);
  // The threshold is the vessel's own diameter: above it the value is frozen as before.
  EXPECT_EQ(apparent_viscosity(rat, 1e-3), apparent_viscosity(rat, rat.pries_max_diameter));
  // The phase separation law was fitted to rat networks: rat cells see the diameter as it
  // is, human cells (92 fl) (55/92)^(1/3) = 0.8424128 of it.
  EXPECT_EQ(rat.phase_separation_diameter_scale(), 1.0);
  expect_relative(human.phase_separation_diameter_scale(), 0.8424127940950442, 1e-14);
}

TEST(ApparentViscosity, NewtonianIgnoresDiameterAndHematocrit) {
  Blood blood;
  blood.rheology = Rheology::newtonian;
  for (double d : {5 * um, 50 * um, 300 * um, 1e-2}) EXPECT_EQ(apparent_viscosity(blood, d), 3.4e-3);
  blood.hematocrit = 0.2;
  EXPECT_EQ(apparent_viscosity(blood, 5 * um), 3.4e-3);
}

// alpha = 4/3 (parabolic profile): R = 2 pi mu alpha/(alpha - 1) l / A^2 = 128 mu l / (pi D^4).
TEST(PoiseuilleResistance, HagenPoiseuilleForParabolicProfile) {
  const double mu = 3.4e-3, length = 1.5e-3, diameter = 40 * um;
  const double hagen = 128 * mu * length / (std::numbers::pi * std::pow(diameter, 4));
  expect_relative(poiseuille_resistance(mu, length, diameter, 4.0 / 3.0), hagen, 1e-13);
  // By hand (mpmath): 128 * 3.4e-3 * 1.5e-3 / (pi * (40e-6)^4) = 6.528e-4 / (pi * 2.56e-18)
  //                  = 8.1169020976866621e13 Pa s / m^3
  expect_relative(poiseuille_resistance(mu, length, diameter, 4.0 / 3.0), 8.1169020976866621e13,
                  1e-12);
}

// The transport's per-vessel viscosity factor (physics/rheology.hpp: HematocritScaling)
// against the law evaluated whole at both hematocrits: capillaries, the zero of C near
// 8.05 um, arterioles, beyond the law's threshold, and rat red cells (the size scaling).
TEST(HematocritScaling, IsTheLawsRatioAtEachHematocrit) {
  for (const double mcv : {92e-18, 55e-18}) {
    Blood blood;
    blood.hematocrit = 0.42;
    blood.mean_cell_volume = mcv;
    for (const double d : {3e-6, 5e-6, 8.05e-6, 8.0517e-6, 12e-6, 40e-6, 300e-6, 2e-3}) {
      const HematocritScaling scaling(blood, d);
      for (const double h : {0.0, 0.05, 0.2, 0.42, 0.6, 0.9}) {
        Blood own = blood;
        own.hematocrit = h;
        const double expected = apparent_viscosity(own, d) / apparent_viscosity(blood, d);
        EXPECT_NEAR(scaling(h), expected, 1e-13 * expected) << "D " << d << " H " << h << " MCV " << mcv;
      }
    }
  }
  Blood newtonian;
  newtonian.rheology = Rheology::newtonian;
  EXPECT_EQ(HematocritScaling(newtonian, 10e-6)(0.1), 1.0);
  EXPECT_EQ(HematocritScaling()(0.3), 1.0);
}
