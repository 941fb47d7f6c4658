// Apparent viscosity of blood in a tube: the Fahraeus-Lindqvist effect through the in vivo
// law of Pries et al. (1994), with the exponents of the published law (ERRATA.md s. 1).
#pragma once

#include <cmath>

#include "physics/blood.hpp"

namespace hemotree {

// Relative apparent viscosity eta (blood / plasma) in vivo, Pries et al. 1994, Circ Res
// 75:904, eqs. with D in micrometres; here diameter in metres. Defined for D > 1.1 um and
// 0 <= hematocrit < 1; throws InputError outside (and for NaN). At hematocrit 0 it is the
// wall-layer factor (D / (D - 1.1))^2, which tends to 1 in large vessels. See docs/physics.md.
double pries_relative_viscosity(double diameter, double hematocrit);

// The dynamic viscosity mu [Pa s] used in the friction term and in Poiseuille resistances:
// Pries: plasma viscosity x eta(s D, H_d) for D < pries_max_diameter, and the value at that
// threshold above it (continuous), s = (92 fl / MCV)^(1/3) the red cells' size against the
// human ones (Blood::pries_diameter_scale); Newtonian: blood.newtonian_viscosity.
double apparent_viscosity(const Blood& blood, double diameter);

// apparent_viscosity at one diameter and another hematocrit, over its value at the blood's:
// eta = [1 + (eta045 - 1) F(H, C) k] k is affine in F, and F in expm1(C ln(1 - H)), so with
// the diameter's terms taken once an evaluation costs a log1p and an expm1 (the whole law
// four exponentials and three powers): what a transport updating millions of vessels' viscosities
// every step can afford. 1 for Newtonian blood.
class HematocritScaling {
 public:
  HematocritScaling() = default;  // 1 everywhere
  HematocritScaling(const Blood& blood, double diameter);
  double operator()(double hematocrit) const {
    if (slope_ == 0) return 1.0;
    const double f = exponent_ == 0 ? std::log1p(-hematocrit) : std::expm1(exponent_ * std::log1p(-hematocrit));
    return (1 + slope_ * f) * scale_;
  }

 private:
  double exponent_ = 0;  // C
  double slope_ = 0;     // (eta045 - 1) k over F's denominator
  double scale_ = 1;     // 1 / (1 + slope F(H_blood)), k cancelling with the blood's value
};

}  // namespace hemotree
