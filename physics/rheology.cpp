// The in vivo apparent viscosity law of Pries et al. (1994), Circ Res 75:904-915, in the form
// of Pries & Secomb (2005), Am J Physiol Heart 289:H2657, with the published exponents 0.645
// and -0.075 (the source paper prints 0.0645 and -0.0075: ERRATA.md s. 1). D in micrometres:
//
//   eta    = [1 + (eta045 - 1) F(H_d, C) k(D)] k(D),        k(D) = (D / (D - 1.1))^2
//   F      = ((1 - H_d)^C - 1) / ((1 - 0.45)^C - 1)
//   eta045 = 6 exp(-0.085 D) + 3.2 - 2.44 exp(-0.06 D^0.645)
//   C      = (0.8 + exp(-0.075 D)) (-1 + s) + s,             s = 1 / (1 + 1e-11 D^12)
#include "physics/rheology.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/errors.hpp"

namespace hemotree {

namespace {

constexpr double metres_to_micrometres = 1e6;
// The law's wall-layer width: k(D) is singular at D = 1.1 um, so the law needs D > 1.1 um.
constexpr double singular_diameter_um = 1.1;

// F(H_d, C) = ((1 - H_d)^C - 1) / (0.55^C - 1), the hematocrit dependence normalised to 1 at
// H_d = 0.45. C changes sign near D = 8.05 um (from about +1 in capillaries to -0.8 in large
// vessels), where numerator and denominator both vanish: F -> ln(1 - H_d) / ln(0.55) there.
// Written as x^C - 1 = expm1(C ln x), both differences keep full relative precision however
// small C is, so F is accurate through the zero of C instead of losing digits as
// eps / |C| near it (0/0 exactly at it).
double hematocrit_factor(double hematocrit, double c) {
  const double log_plasma_fraction = std::log1p(-hematocrit);  // ln(1 - H_d), exact at H_d = 0
  const double log_reference_fraction = std::log(1 - 0.45);
  if (c == 0) return log_plasma_fraction / log_reference_fraction;
  return std::expm1(c * log_plasma_fraction) / std::expm1(c * log_reference_fraction);
}

// The law's terms in D alone [um].
struct DiameterTerms {
  double k, eta045, c;
};
DiameterTerms diameter_terms(double d) {
  DiameterTerms t;
  t.k = std::pow(d / (d - singular_diameter_um), 2);
  t.eta045 = 6 * std::exp(-0.085 * d) + 3.2 - 2.44 * std::exp(-0.06 * std::pow(d, 0.645));
  // s switches C from about 1 below ~8 um to -(0.8 + exp(-0.075 D)) above. D^12 overflows
  // only beyond D ~ 1e25 um, and then s = 1 / (1 + inf) = 0 is still the right limit.
  const double s = 1 / (1 + 1e-11 * std::pow(d, 12));
  t.c = (0.8 + std::exp(-0.075 * d)) * (-1 + s) + s;
  return t;
}

}  // namespace

double pries_relative_viscosity(double diameter, double hematocrit) {
  const double d = diameter * metres_to_micrometres;
  // The negated comparisons also refuse NaN.
  if (!(d > singular_diameter_um) || !std::isfinite(d)) {
    std::ostringstream message;
    message << "Pries viscosity law: diameter " << diameter
            << " m is outside its domain (finite and above 1.1 um)";
    throw InputError(message.str());
  }
  if (!(hematocrit >= 0 && hematocrit < 1)) {
    std::ostringstream message;
    message << "Pries viscosity law: discharge hematocrit " << hematocrit
            << " is outside [0, 1)";
    throw InputError(message.str());
  }

  const DiameterTerms t = diameter_terms(d);
  // At H_d = 0, F = 0 and eta = k(D): plasma alone, in a lumen narrowed by the in vivo
  // wall layer; k -> 1 (pure plasma) as D grows.
  return (1 + (t.eta045 - 1) * hematocrit_factor(hematocrit, t.c) * t.k) * t.k;
}

double apparent_viscosity(const Blood& blood, double diameter) {
  switch (blood.rheology) {
    case Rheology::newtonian:
      return blood.newtonian_viscosity;
    case Rheology::pries:
      // Above the threshold the law is frozen at its value there: eta is continuous in D,
      // and the 1D friction of large vessels sees a constant viscosity, as in the paper.
      // Red cells of another size than the human ones the law was fitted to: the diameter
      // the cells see scales as their size, (92 fl / MCV)^(1/3) (Secomb's NetFlow).
      return blood.plasma_viscosity *
             pries_relative_viscosity(std::min(diameter, blood.pries_max_diameter) * blood.pries_diameter_scale(),
                                      blood.hematocrit);
  }
  throw InputError("unknown rheology");  // unreachable for valid enumerators
}

HematocritScaling::HematocritScaling(const Blood& blood, double diameter) {
  if (blood.rheology != Rheology::pries) return;
  // The diameter apparent_viscosity gives the law (frozen above the threshold, scaled by the
  // cells' size); its validity checks are apparent_viscosity's.
  const double blood_viscosity = apparent_viscosity(blood, diameter);
  const double d = std::min(diameter, blood.pries_max_diameter) * blood.pries_diameter_scale() * metres_to_micrometres;
  const DiameterTerms t = diameter_terms(d);
  exponent_ = t.c;
  const double denominator = t.c == 0 ? std::log(1 - 0.45) : std::expm1(t.c * std::log(1 - 0.45));
  slope_ = (t.eta045 - 1) * t.k / denominator;
  // eta(H) / eta(H_blood) with eta = (1 + slope f(H)) k plasma: the k and the plasma cancel.
  scale_ = blood.plasma_viscosity * t.k / blood_viscosity;
}

}  // namespace hemotree
