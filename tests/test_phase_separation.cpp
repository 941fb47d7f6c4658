// Red cells at bifurcations (Pries & Secomb 2005, NetFlow's constants) and in tubes (the
// Fahraeus effect, Pries et al. 1992): physics/phase_separation.hpp.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "core/errors.hpp"
#include "physics/phase_separation.hpp"

using namespace hemotree;

namespace {

constexpr double um = 1e-6;
constexpr double not_a_number = std::numeric_limits<double>::quiet_NaN();
constexpr double inf = std::numeric_limits<double>::infinity();

// A 10 um feed at H_F = 0.45 dividing into 8 um (daughter 1) and 6 um (daughter 2).
Bifurcation asymmetric(double flow_fraction) {
  Bifurcation b;
  b.feed_diameter = 10 * um;
  b.first_diameter = 8 * um;
  b.second_diameter = 6 * um;
  b.flow_fraction = flow_fraction;
  b.feed_hematocrit = 0.45;
  return b;
}

}  // namespace

// Reference values, computed independently of this code from the published formulas with
// Python's mpmath at 50 significant digits (python3, mpmath 1.3.0):
//
//   D_F = 10 um, D_1 = 8 um, D_2 = 6 um, H_F = 0.45 (scale 1):
//     X0 = 0.964 * 0.55 / 10 = 0.05302, B = 1 + 6.98 * 0.055 = 1.3839,
//     A = -13.29 * (64/36 - 1) / (64/36 + 1) * 0.055 = -13.29 * 0.28 * 0.055 = -0.204666
//     FQB = 0.6:  FQE = 0.60472911520023732, H_1 = 0.45354683640017799, H_2 = 0.44467974539973302
//     FQB = 0.3:  FQE = 0.17691751703295296, H_1 = 0.26537627554942945, H_2 = 0.52912445333595881
//     FQB = 0.06: FQE = 0.0009974126508729312, H_1 = 0.007480594881546984,
//                 H_2 = 0.47824591947564594
//   the same with MCV 55 fl, scale (92/55)^(1/3) = 1.1870664916411232 (D_F seen as 11.87 um):
//     X0 = 0.044664726342919242, A = -0.17241325691625631, B = 1.3234022716530875
//     FQB = 0.3:  FQE = 0.19469107897246758, H_1 = 0.29203661845870137, H_2 = 0.51769859208912798
//
// Double arithmetic through exp and log keeps about 15 digits; 1e-12 relative is generous.
TEST(PhaseSeparation, ParametersMatchTheHandComputedOnes) {
  const PhaseSeparationLaw law = phase_separation_law(asymmetric(0.5));
  EXPECT_NEAR(law.x0, 0.05302, 1e-15);
  EXPECT_NEAR(law.a, -0.204666, 1e-15);
  EXPECT_NEAR(law.b, 1.3839, 1e-15);
}

TEST(PhaseSeparation, RedCellFractionMatchesMpmath) {
  EXPECT_NEAR(red_cell_fraction(asymmetric(0.6)), 0.60472911520023732, 1e-12);
  EXPECT_NEAR(red_cell_fraction(asymmetric(0.3)), 0.17691751703295296, 1e-12);
  EXPECT_NEAR(red_cell_fraction(asymmetric(0.06)), 0.0009974126508729312, 1e-15);

  const DaughterHematocrits at_03 = daughter_hematocrits(asymmetric(0.3));
  EXPECT_NEAR(at_03.first, 0.26537627554942945, 1e-12);
  EXPECT_NEAR(at_03.second, 0.52912445333595881, 1e-12);
  const DaughterHematocrits at_06 = daughter_hematocrits(asymmetric(0.6));
  EXPECT_NEAR(at_06.first, 0.45354683640017799, 1e-12);
  EXPECT_NEAR(at_06.second, 0.44467974539973302, 1e-12);
  const DaughterHematocrits at_006 = daughter_hematocrits(asymmetric(0.06));
  EXPECT_NEAR(at_006.first, 0.007480594881546984, 1e-14);
  EXPECT_NEAR(at_006.second, 0.47824591947564594, 1e-12);
}

TEST(PhaseSeparation, MeanCellVolumeScalesOnlyTheFeedDiameter) {
  Bifurcation rat = asymmetric(0.3);
  rat.diameter_scale = std::cbrt(92.0 / 55.0);
  const PhaseSeparationLaw law = phase_separation_law(rat);
  EXPECT_NEAR(law.x0, 0.044664726342919242, 1e-15);
  EXPECT_NEAR(law.a, -0.17241325691625631, 1e-14);
  EXPECT_NEAR(law.b, 1.3234022716530875, 1e-14);
  EXPECT_NEAR(red_cell_fraction(rat), 0.19469107897246758, 1e-12);
  const DaughterHematocrits daughters = daughter_hematocrits(rat);
  EXPECT_NEAR(daughters.first, 0.29203661845870137, 1e-12);
  EXPECT_NEAR(daughters.second, 0.51769859208912798, 1e-12);
}

// Equal daughters and an equal split: A = 0 and logit(1/2) = 0, so FQE = 1/2 exactly and
// both daughters carry the feed's hematocrit.
TEST(PhaseSeparation, SymmetricBifurcationSplitsRedCellsEvenly) {
  Bifurcation b = asymmetric(0.5);
  b.second_diameter = b.first_diameter;
  EXPECT_EQ(phase_separation_law(b).a, 0.0);
  EXPECT_DOUBLE_EQ(red_cell_fraction(b), 0.5);
  const DaughterHematocrits daughters = daughter_hematocrits(b);
  EXPECT_DOUBLE_EQ(daughters.first, 0.45);
  EXPECT_DOUBLE_EQ(daughters.second, 0.45);
}

// Naming the daughters the other way round (D_1 <-> D_2, FQB -> 1 - FQB) flips the sign of A
// and of the logit, so FQE -> 1 - FQE: the law has no preferred daughter.
TEST(PhaseSeparation, RelabellingTheDaughtersMirrorsTheLaw) {
  for (double fqb : {0.02, 0.06, 0.2, 0.5, 0.7, 0.95, 0.99}) {
    const Bifurcation b = asymmetric(fqb);
    Bifurcation mirrored = b;
    std::swap(mirrored.first_diameter, mirrored.second_diameter);
    mirrored.flow_fraction = 1 - fqb;
    EXPECT_NEAR(red_cell_fraction(mirrored), 1 - red_cell_fraction(b), 1e-14) << "FQB " << fqb;
    EXPECT_NEAR(daughter_hematocrits(mirrored).first, daughter_hematocrits(b).second, 1e-13);
  }
}

// Red cells are neither made nor lost: FQB H_1 + (1 - FQB) H_2 = H_F at every split,
// i.e. Q_1 H_1 + Q_2 H_2 = Q_F H_F with Q_1 = FQB Q_F.
TEST(PhaseSeparation, ConservesRedCells) {
  for (int i = 0; i <= 200; ++i) {
    const double fqb = i / 200.0;
    const Bifurcation b = asymmetric(fqb);
    const DaughterHematocrits d = daughter_hematocrits(b);
    EXPECT_NEAR(fqb * d.first + (1 - fqb) * d.second, b.feed_hematocrit, 1e-15) << "FQB " << fqb;
    EXPECT_GE(d.first, 0.0);
    EXPECT_GE(d.second, 0.0);
  }
}

// A daughter drawing at most X0 of the flow skims plasma alone; at most X0 left for the
// other, and that one gets none. The flowless daughter's hematocrit is the skimming limit 0.
TEST(PhaseSeparation, ThresholdsAndFlowlessDaughters) {
  const double x0 = 0.05302;
  for (double fqb : {0.0, 0.01, 0.05, x0}) {
    EXPECT_EQ(red_cell_fraction(asymmetric(fqb)), 0.0) << "FQB " << fqb;
    EXPECT_EQ(daughter_hematocrits(asymmetric(fqb)).first, 0.0);
    EXPECT_NEAR(daughter_hematocrits(asymmetric(fqb)).second, 0.45 / (1 - fqb), 1e-15);
  }
  for (double fqb : {1 - x0, 0.96, 0.99, 1.0}) {
    EXPECT_EQ(red_cell_fraction(asymmetric(fqb)), 1.0) << "FQB " << fqb;
    EXPECT_EQ(daughter_hematocrits(asymmetric(fqb)).second, 0.0);
    EXPECT_NEAR(daughter_hematocrits(asymmetric(fqb)).first, 0.45 / fqb, 1e-15);
  }
  // Continuous at the thresholds: B > 0, so FQE -> 0 as FQB -> X0 from above, as
  // ((FQB - X0) / (1 - 2 X0))^B e^A.
  EXPECT_LT(red_cell_fraction(asymmetric(x0 + 1e-9)), 1e-10);
  EXPECT_GT(red_cell_fraction(asymmetric(1 - x0 - 1e-9)), 1 - 1e-10);
}

TEST(PhaseSeparation, RedCellFractionGrowsWithTheFlowFraction) {
  double previous = -1;
  for (int i = 0; i <= 1000; ++i) {
    const double fqe = red_cell_fraction(asymmetric(i / 1000.0));
    EXPECT_GE(fqe, previous) << "FQB " << i / 1000.0;
    EXPECT_LE(fqe, 1.0);
    previous = fqe;
  }
}

// Phase separation fades as the feed widens: (1 - H_F) / D_F -> 0 gives X0 -> 0, A -> 0,
// B -> 1 and FQE -> FQB. At D_F = 1 mm (800 and 600 um daughters, H_F = 0.45, FQB = 0.3)
// mpmath gives FQE = 0.29867563199621939: 1.3e-3 below FQB.
TEST(PhaseSeparation, WideFeedsDoNotSeparate) {
  Bifurcation b = asymmetric(0.3);
  b.feed_diameter = 1000 * um;
  b.first_diameter = 800 * um;
  b.second_diameter = 600 * um;
  EXPECT_NEAR(red_cell_fraction(b), 0.29867563199621939, 1e-12);
  EXPECT_NEAR(red_cell_fraction(b), 0.3, 2e-3);
}

TEST(PhaseSeparation, RefusesInputsOutsideTheDomain) {
  const auto refused = [](auto change) {
    Bifurcation b = asymmetric(0.3);
    change(b);
    EXPECT_THROW(red_cell_fraction(b), InputError);
    EXPECT_THROW(daughter_hematocrits(b), InputError);
  };
  for (double h : {1.0, -0.1, 1.5, not_a_number}) refused([h](Bifurcation& b) { b.feed_hematocrit = h; });
  for (double d : {0.0, -8 * um, inf, not_a_number}) {
    refused([d](Bifurcation& b) { b.feed_diameter = d; });
    refused([d](Bifurcation& b) { b.first_diameter = d; });
    refused([d](Bifurcation& b) { b.second_diameter = d; });
    refused([d](Bifurcation& b) { b.diameter_scale = d; });
  }
  for (double q : {-0.1, 1.1, not_a_number}) refused([q](Bifurcation& b) { b.flow_fraction = q; });

  // X0 = 0.964 (1 - H_F) / D_F reaches 1/2 at D_F = 1.928 (1 - H_F) um: 1.5424 um at 0.2.
  Bifurcation narrow = asymmetric(0.5);
  narrow.feed_hematocrit = 0.2;
  narrow.feed_diameter = 1.5 * um;
  EXPECT_THROW(red_cell_fraction(narrow), InputError);
  narrow.feed_diameter = 1.6 * um;
  EXPECT_NO_THROW(red_cell_fraction(narrow));

  try {
    Bifurcation b = asymmetric(0.3);
    b.feed_hematocrit = 1.0;
    red_cell_fraction(b);
    FAIL() << "no InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("feed discharge hematocrit 1 is outside [0, 1)"),
              std::string::npos)
        << error.what();
  }
}

// 2 nl/min at 0.45 and 1 nl/min at 0.30 mix to (0.9 + 0.3) / 3 = 0.4; red-cell flux is kept.
TEST(HematocritMixing, FlowWeightedMean) {
  const std::vector<double> flows{2.0 / 6e13, 1.0 / 6e13};
  const std::vector<double> hematocrits{0.45, 0.30};
  EXPECT_NEAR(mixed_hematocrit(flows, hematocrits), 0.4, 1e-15);
  EXPECT_NEAR(mixed_hematocrit(std::vector<double>{1.0}, std::vector<double>{0.3}), 0.3, 0);
  // A stagnant inflow adds nothing; no inflow at all gives 0.
  EXPECT_NEAR(mixed_hematocrit(std::vector<double>{0.0, 1e-12}, std::vector<double>{0.9, 0.2}),
              0.2, 1e-15);
  EXPECT_EQ(mixed_hematocrit(std::vector<double>{0.0, 0.0}, std::vector<double>{0.4, 0.2}), 0.0);
  EXPECT_EQ(mixed_hematocrit(std::vector<double>{}, std::vector<double>{}), 0.0);
}

TEST(HematocritMixing, RefusesInputsOutsideTheDomain) {
  const std::vector<double> one_flow{1e-12};
  EXPECT_THROW(mixed_hematocrit(one_flow, std::vector<double>{0.4, 0.4}), InputError);
  for (double q : {-1e-12, inf, not_a_number})
    EXPECT_THROW(mixed_hematocrit(std::vector<double>{q}, std::vector<double>{0.4}), InputError);
  for (double h : {1.0, -0.1, not_a_number})
    EXPECT_THROW(mixed_hematocrit(one_flow, std::vector<double>{h}), InputError);
}

// Fahraeus, H_T = H_D (H_D + (1 - H_D) X), X = 1 + 1.7 e^(-0.415 D) - 0.6 e^(-0.011 D),
// mpmath at 50 digits:
//   H_D = 0.45, D = 10 um:   H_T = 0.32360150914446808
//   H_D = 0.30, D = 4 um:    H_T = 0.24730341725463895
//   H_D = 0.45, D = 5 um:    H_T = 0.36227482239667038
//   H_D = 0.45, D = 1000 um: H_T = 0.44999751979743265
//   H_D = 0.45, D = 2 um:    H_T = 0.48819906231468141 (X > 1 below D = 2.5778561 um)
//   H_D = 0.45, D = 10 um x (92/55)^(1/3): H_T = 0.32272982987486631
TEST(Fahraeus, TubeHematocritMatchesMpmath) {
  EXPECT_NEAR(tube_hematocrit(0.45, 10 * um), 0.32360150914446808, 1e-14);
  EXPECT_NEAR(tube_hematocrit(0.30, 4 * um), 0.24730341725463895, 1e-14);
  EXPECT_NEAR(tube_hematocrit(0.45, 5 * um), 0.36227482239667038, 1e-14);
  EXPECT_NEAR(tube_hematocrit(0.45, 1000 * um), 0.44999751979743265, 1e-14);
  EXPECT_NEAR(tube_hematocrit(0.45, 2 * um), 0.48819906231468141, 1e-14);
  EXPECT_NEAR(tube_hematocrit(0.45, 10 * um, std::cbrt(92.0 / 55.0)), 0.32272982987486631, 1e-14);
}

// Red cells outrun the plasma, so a tube holds fewer of them than the blood leaving it
// carries: H_T < H_D from 2.58 um up, with H_T -> H_D as the tube widens; no cells, none inside.
TEST(Fahraeus, TubeHematocritIsBelowDischargeAndApproachesItInLargeVessels) {
  for (double h : {0.1, 0.3, 0.45, 0.6, 0.9}) {
    for (double d = 2.6; d <= 3000; d *= 1.1) {
      EXPECT_LT(tube_hematocrit(h, d * um), h) << "H_D " << h << ", D " << d << " um";
    }
    EXPECT_NEAR(tube_hematocrit(h, 1 * 1e-2), h, 1e-15 * h) << "H_D " << h << " in 1 cm";
  }
  EXPECT_EQ(tube_hematocrit(0.0, 10 * um), 0.0);
}

TEST(Fahraeus, RefusesInputsOutsideTheDomain) {
  for (double h : {1.0, -0.1, not_a_number}) EXPECT_THROW(tube_hematocrit(h, 10 * um), InputError);
  for (double d : {0.0, -1 * um, inf, not_a_number}) {
    EXPECT_THROW(tube_hematocrit(0.45, d), InputError);
    EXPECT_THROW(tube_hematocrit(0.45, 10 * um, d), InputError);
  }
}

namespace hemotree {
namespace {
// law_splits is the domain phase_separation_law refuses outside: X0 < 1/2, a scaled feed
// wider than 2 x 0.964 (1 - H_F) um (1.0604 um at H_F 0.45).
TEST(PhaseSeparation, LawSplitsWhereItsThresholdIsBelowOneHalf) {
  Bifurcation b;
  b.first_diameter = b.second_diameter = 1e-6;
  b.flow_fraction = 0.5;
  b.feed_hematocrit = 0.45;
  b.feed_diameter = 1.07e-6;
  EXPECT_TRUE(law_splits(b));
  EXPECT_NO_THROW(phase_separation_law(b));
  b.feed_diameter = 1.05e-6;
  EXPECT_FALSE(law_splits(b));
  EXPECT_THROW(phase_separation_law(b), InputError);
  b.diameter_scale = 1.1;  // the cells' size moves the edge
  EXPECT_TRUE(law_splits(b));
}
}  // namespace
}  // namespace hemotree
