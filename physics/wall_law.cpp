// The tube law's beta, p_ref and A_ref for thin- and thick-walled vessels, after Causin et
// al. (2017) as given in the source paper (eqs. wall and h_undeformed).
#include "physics/wall_law.hpp"

#include <cmath>
#include <numbers>
#include <sstream>
#include <string>

#include "core/errors.hpp"

namespace hemotree {

namespace {

const double sqrt_pi = std::sqrt(std::numbers::pi);

[[noreturn]] void refuse(const std::string& what, double value) {
  std::ostringstream message;
  message << "wall law: " << what << " (got " << value << ")";
  throw InputError(message.str());
}

// The negated comparisons also refuse NaN.
void check_geometry(const WallProperties& wall) {
  if (!(wall.diameter > 0) || !std::isfinite(wall.diameter))
    refuse("lumen diameter must be positive and finite [m]", wall.diameter);
  if (!(wall.wall_thickness > 0) || !std::isfinite(wall.wall_thickness))
    refuse("wall thickness must be positive and finite [m]", wall.wall_thickness);
}

void check_material(const WallProperties& wall, double external_pressure,
                    double poisson_ratio) {
  check_geometry(wall);
  if (!(wall.youngs_modulus > 0) || !std::isfinite(wall.youngs_modulus))
    refuse("Young's modulus must be positive and finite [Pa]", wall.youngs_modulus);
  // An isotropic linear-elastic solid has -1 < nu <= 1/2 (1/2: incompressible).
  if (!(poisson_ratio > -1 && poisson_ratio <= 0.5))
    refuse("Poisson ratio must lie in (-1, 0.5]", poisson_ratio);
  if (!std::isfinite(external_pressure))
    refuse("external pressure must be finite [Pa]", external_pressure);
}

}  // namespace

// --- Choice of model ------------------------------------------------------------------------

// The threshold is a ratio given in decimal (0.1) and met exactly by walls given as h = 10 % D,
// but h / D computed in binary can land an ulp above 0.1. The relative tolerance keeps such
// walls thin, as intended, without moving any real threshold.
WallModel choose_wall_model(const WallProperties& wall, double thick_ratio) {
  check_geometry(wall);
  if (!(thick_ratio > 0)) refuse("thick-wall ratio h/D must be positive", thick_ratio);
  constexpr double relative_tolerance = 1e-9;
  return wall.wall_thickness <= thick_ratio * wall.diameter * (1 + relative_tolerance)
             ? WallModel::thin
             : WallModel::thick;
}

// --- Thin wall ------------------------------------------------------------------------------

// Laplace's law for a thin cylindrical membrane: the measured geometry is the one at zero
// transmural pressure, so p_ref = p_ext and A_ref = pi R^2.
TubeLaw thin_wall_tube_law(const WallProperties& wall, double external_pressure,
                           double poisson_ratio) {
  check_material(wall, external_pressure, poisson_ratio);
  const double r = wall.diameter / 2;
  TubeLaw law;
  law.beta = wall.youngs_modulus * wall.wall_thickness /
             ((1 - poisson_ratio * poisson_ratio) * sqrt_pi * r * r);
  law.reference_pressure = external_pressure;
  law.reference_area = std::numbers::pi * r * r;
  return law;
}

// --- Thick wall -----------------------------------------------------------------------------

// The reference state (R_ref, h_ref) is the stress-free ring. The measured ring (R_0, h_0)
// is taken at zero transmural pressure: lumen and outside both at p_ext, a uniform
// compression (sigma_r = sigma_theta = -p_ext, plane stress) that shrinks the lumen radius
// by the factor (1 - (1 - nu) p_ext / E). The paper then fixes h_ref by conserving the wall's
// cross-sectional area (an incompressible wall):
//   (R_ref + h_ref)^2 - R_ref^2 = (R_0 + h_0)^2 - R_0^2.
// With b = R_ref + h_ref and den = (1 - nu) R_ref^2 + (1 + nu) b^2,
//   p_ref = 2 b^2 p_ext / den,   beta = E (b^2 - R_ref^2) / (den R_ref sqrt(pi)).
// These make p(pi R_0^2) = p_ext exactly, not only to first order in p_ext / E:
//   beta sqrt(pi) (R_0 - R_ref) = -(1 - nu) (b^2 - R_ref^2) p_ext / den,
// so p(pi R_0^2) = [2 b^2 - (1 - nu)(b^2 - R_ref^2)] p_ext / den = p_ext, whatever h_ref is.
// As h -> 0 beta tends to E h / (sqrt(pi) R^2), not to the thin-wall value: the two models
// differ by 1 / (1 - nu^2) (ERRATA.md s. 4), and neither is a limit of the other.
TubeLaw thick_wall_tube_law(const WallProperties& wall, double external_pressure,
                            double poisson_ratio) {
  check_material(wall, external_pressure, poisson_ratio);
  const double e = wall.youngs_modulus;
  const double shrink = 1 - (1 - poisson_ratio) * external_pressure / e;
  if (!(shrink > 0))
    refuse("(1 - nu) p_ext must stay below Young's modulus, or the stress-free radius "
           "is not defined; p_ext [Pa]",
           external_pressure);

  const double r0 = wall.diameter / 2;
  const double h0 = wall.wall_thickness;
  const double r_ref = r0 / shrink;
  // sqrt(R_ref^2 + w) - R_ref with w = h0 (h0 + 2 R0), written without the cancellation
  // that the difference suffers when the wall is thin against the lumen.
  const double wall_area_over_pi = h0 * (h0 + 2 * r0);
  const double h_ref = wall_area_over_pi / (std::sqrt(r_ref * r_ref + wall_area_over_pi) + r_ref);
  const double b = r_ref + h_ref;
  const double den = (1 - poisson_ratio) * r_ref * r_ref + (1 + poisson_ratio) * b * b;

  TubeLaw law;
  law.beta = e * wall_area_over_pi / den / (r_ref * sqrt_pi);  // b^2 - R_ref^2 = h0 (h0 + 2 R0)
  law.reference_pressure = 2 * b * b / den * external_pressure;
  law.reference_area = std::numbers::pi * r_ref * r_ref;
  return law;
}

TubeLaw tube_law(const WallProperties& wall, double external_pressure, double thick_ratio,
                 double poisson_ratio) {
  return choose_wall_model(wall, thick_ratio) == WallModel::thin
             ? thin_wall_tube_law(wall, external_pressure, poisson_ratio)
             : thick_wall_tube_law(wall, external_pressure, poisson_ratio);
}

double thin_wall_tapered_compliance(double length, double d0, double d1, double wall_thickness,
                                    double youngs_modulus, double poisson_ratio) {
  const double r0 = d0 / 2, r1 = d1 / 2;
  const double cubes = r0 * r0 * r0 + r0 * r0 * r1 + r0 * r1 * r1 + r1 * r1 * r1;
  return 2 * std::numbers::pi * (1 - poisson_ratio * poisson_ratio) / (youngs_modulus * wall_thickness) * length *
         cubes / 4;
}

}  // namespace hemotree
