// The wall models that give a vessel's tube law p = p_ref + beta (sqrt(A) - sqrt(A_ref))
// (physics/tube_law.hpp) from its wall: beta and p_ref from the thin- or thick-walled models
// of Causin et al. (the paper's eqs. wall and h_undeformed), chosen per vessel by its wall
// thickness to diameter ratio. The laws they return carry no blood yet (density 0): the
// solvers that need its wave speed or fluxes set density and alpha.
#pragma once

#include "physics/tube_law.hpp"

namespace hemotree {

enum class WallModel { thin, thick };

struct WallProperties {
  double diameter = 0;          // lumen diameter at zero transmural pressure [m]
  double wall_thickness = 0;    // [m]
  double youngs_modulus = 0;    // [Pa]
};

inline constexpr double default_poisson_ratio = 0.5;
// h/D at or below which a wall is thin (capillaries, h = 10 % D); above it, thick.
inline constexpr double default_thick_wall_ratio = 0.1;

// Thin when h <= thick_ratio D, with a relative tolerance of 1e-9 so that h = 10 % D given in
// decimal stays thin whatever binary rounding does to h / D. Throws InputError unless D, h > 0.
WallModel choose_wall_model(const WallProperties& wall, double thick_ratio = default_thick_wall_ratio);

// Thin wall: p_ref = p_ext, A_ref = A(dp_t = 0), beta = E h / ((1 - nu^2) sqrt(pi) R^2).
TubeLaw thin_wall_tube_law(const WallProperties& wall, double external_pressure,
                           double poisson_ratio = default_poisson_ratio);
// Thick wall: the unloaded (R_ref, h_ref) from the measured geometry taken at zero
// transmural pressure, then p_ref and beta from Causin et al. The result gives
// p(pi (D/2)^2) = p_ext exactly. It is not the thin-wall law in the limit h -> 0 (beta
// differs by 1 - nu^2: ERRATA.md s. 4). Requires (1 - nu) p_ext < E.
// All the tube-law factories throw InputError for non-positive or non-finite D, h or E, for
// nu outside (-1, 1/2], or for a non-finite p_ext.
TubeLaw thick_wall_tube_law(const WallProperties& wall, double external_pressure,
                            double poisson_ratio = default_poisson_ratio);
TubeLaw tube_law(const WallProperties& wall, double external_pressure,
                 double thick_ratio = default_thick_wall_ratio,
                 double poisson_ratio = default_poisson_ratio);

// Compliance at the reference lumen, int_0^L dA/dp dx [m^3/Pa], of a thin-walled vessel whose
// radius is linear from d0/2 to d1/2 with E and h constant along it (as openBF's tapered
// vessels): dA/dp = 2 sqrt(A) / beta = 2 pi (1 - nu^2) R^3 / (E h), and int R^3 dx =
// L (R0^3 + R0^2 R1 + R0 R1^2 + R1^3) / 4.
double thin_wall_tapered_compliance(double length, double d0, double d1, double wall_thickness,
                                    double youngs_modulus, double poisson_ratio = default_poisson_ratio);

}  // namespace hemotree
