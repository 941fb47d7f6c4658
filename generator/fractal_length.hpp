// The length law l = zeta r^gamma of a fractal vascular tree (Kamiya & Takahashi 2007,
// J Appl Physiol 102:2315): zeta follows from the tree's fractal dimension d_f, the radii of
// its largest and smallest vessels and its volume. SI units, radii (not diameters).
#pragma once

namespace hemotree {

struct FractalCalibration {
  double radius_max = 0;          // [m]
  double radius_min = 0;          // [m]
  double volume = 0;              // [m^3]
  double fractal_dimension = 0;   // d_f
};

// iota   = d_f / (R_min^-d_f - R_max^-d_f)
// lambda = V (2 - d_f) / (pi iota (R_max^(2-d_f) - R_min^(2-d_f)))
// zeta   = lambda iota / R_max^(d_f + gamma)
double length_scale_zeta(const FractalCalibration& c, double gamma);

}  // namespace hemotree
