// Apparent viscosity of blood in a tube: the Fahraeus-Lindqvist effect through the in vivo
// law of Pries et al. (1994), with the exponents of the published law (ERRATA.md s. 1).
#pragma once

#include "formats/boundary_conditions.hpp"

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

}  // namespace hemotree
