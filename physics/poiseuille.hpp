// Steady viscous resistance of a vessel with the velocity profile of the 1D model.
#pragma once

#include <numbers>

namespace hemotree {

// Friction f = -2 pi mu alpha/(alpha - 1) u per unit length gives, in steady flow,
// dp/dx = -2 pi mu alpha/(alpha - 1) Q / A^2, so R = 2 pi mu alpha/(alpha - 1) l / A^2;
// alpha = 4/3 (Poiseuille) gives R = 128 mu l / (pi D^4).
inline double poiseuille_resistance(double viscosity, double length, double diameter,
                                    double alpha) {
  const double area = std::numbers::pi / 4 * diameter * diameter;
  return 2 * std::numbers::pi * viscosity * alpha / (alpha - 1) * length / (area * area);
}

}  // namespace hemotree
