// Red cells at bifurcations and in tubes: the laws a hematocrit transport needs.
//
// Phase separation at a diverging bifurcation: the empirical law of Pries & Secomb (2005),
// Am J Physiol Heart Circ Physiol 289:H2657, with the constants of Secomb's NetFlow
// (RheolParams.dat "bifpar" 0.964, 6.98, -13.29; dishem.cpp). Fahraeus effect: the tube
// hematocrit from the discharge hematocrit, Pries, Neuhaus & Gaehtgens (1992), Am J Physiol
// 263:H1770. Formulas, edge cases and test values: docs/physics.md.
#pragma once

#include <span>

namespace hemotree {

// One feeding vessel dividing into two daughters. Diameters in metres; the law itself reads
// micrometres after multiplying by diameter_scale.
struct Bifurcation {
  double feed_diameter = 0;     // D_F [m]
  double first_diameter = 0;    // D_1, the daughter flow_fraction refers to [m]
  double second_diameter = 0;   // D_2 [m]
  double flow_fraction = 0;     // FQB: fraction of the feed's blood flow into daughter 1, [0, 1]
  double feed_hematocrit = 0;   // H_F: the feed's discharge hematocrit, [0, 1)
  // (92 fl / MCV)^(1/3), Blood::pries_diameter_scale(): the diameter red cells of another
  // size see. It changes only D_F (the diameter ratio is scale free). 1 reproduces
  // NetFlow's dishem.cpp, which does not scale (its viscor.cpp does).
  double diameter_scale = 1;
};

// The law's three parameters for a bifurcation (all dimensionless):
//   X0 = 0.964 (1 - H_F) / D_F                      the plasma-skimming threshold
//   A  = -13.29 (R - 1) / (R + 1) (1 - H_F) / D_F,  R = (D_1 / D_2)^2, the asymmetry
//   B  = 1 + 6.98 (1 - H_F) / D_F                    the steepness
// D_F in micrometres (scaled). Throws InputError outside the domain (see red_cell_fraction).
struct PhaseSeparationLaw {
  double x0 = 0;
  double a = 0;
  double b = 0;
};
PhaseSeparationLaw phase_separation_law(const Bifurcation& bifurcation);
// Whether the law splits this feed at all: X0 < 1/2 (a scaled feed wider than
// 1.928 (1 - H_F) um). Does not throw; the other arguments are not checked.
bool law_splits(const Bifurcation& bifurcation);

// FQE: the fraction of the feed's red-cell flux that enters daughter 1, in [0, 1]:
//   FQE = 0                                      for FQB <= X0 (daughter 1 gets plasma only)
//   FQE = 1                                      for FQB >= 1 - X0
//   logit FQE = A + B logit((FQB - X0) / (1 - 2 X0))   between,  logit x = ln(x / (1 - x))
// Throws InputError for a non-finite or non-positive diameter or scale, H_F outside [0, 1),
// FQB outside [0, 1], and a feed so narrow that X0 >= 1/2 (scaled D_F <= 1.928 (1 - H_F) um),
// where the law leaves no flow split at which both daughters receive red cells.
double red_cell_fraction(const Bifurcation& bifurcation);

// The daughters' discharge hematocrits from red-cell conservation:
//   H_1 = FQE H_F / FQB,   H_2 = (1 - FQE) H_F / (1 - FQB),
// and 0 for a daughter without flow (FQB = 0 or 1), the limit of plasma skimming as its flow
// vanishes (FQE is 0 for all FQB <= X0). The law does not bound these by 1.
struct DaughterHematocrits {
  double first = 0;
  double second = 0;
};
DaughterHematocrits daughter_hematocrits(const Bifurcation& bifurcation);

// The discharge hematocrit of blood mixed at a node, H = sum Q_i H_i / sum Q_i, over its
// inflows (Q_i >= 0 [m^3/s], H_i in [0, 1)): what a converging node sends on, and NetFlow's
// dishem.cpp rule for every outflow of a node where one vessel feeds more than two (no
// separation there). 0 when no blood flows in. Throws InputError for spans of different
// lengths, a negative or non-finite flow, or a hematocrit outside [0, 1).
double mixed_hematocrit(std::span<const double> inflows, std::span<const double> hematocrits);

// Tube hematocrit H_T (the red-cell volume fraction inside the vessel) from the discharge
// hematocrit H_D (that of the blood leaving it), the Fahraeus effect, Pries et al. 1992 eq. 7:
//   H_T / H_D = H_D + (1 - H_D) (1 + 1.7 exp(-0.415 D) - 0.6 exp(-0.011 D)),  D in um
// with D = diameter_scale x diameter. H_T < H_D for D above 2.58 um and H_T -> H_D in large
// vessels. Throws InputError for H_D outside [0, 1) and a non-finite or non-positive diameter
// or scale.
double tube_hematocrit(double discharge_hematocrit, double diameter, double diameter_scale = 1);
// The law's diameter term k = 1 + 1.7 exp(-0.415 D) - 0.6 exp(-0.011 D) (D in um, scaled), so
// that H_T = H_D (k + (1 - k) H_D): the limit of H_T / H_D as H_D -> 0. Throws InputError for
// a non-finite or non-positive diameter or scale.
double fahraeus_parameter(double diameter, double diameter_scale = 1);

}  // namespace hemotree
