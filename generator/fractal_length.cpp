#include "generator/fractal_length.hpp"

#include <cmath>
#include <numbers>

namespace hemotree {

double length_scale_zeta(const FractalCalibration& c, double gamma) {
  const double df = c.fractal_dimension;
  const double iota = df / (std::pow(c.radius_min, -df) - std::pow(c.radius_max, -df));
  const double lambda = c.volume * (2.0 - df) /
                        (std::numbers::pi * iota *
                         (std::pow(c.radius_max, 2.0 - df) - std::pow(c.radius_min, 2.0 - df)));
  return lambda * iota / std::pow(c.radius_max, df + gamma);
}

}  // namespace hemotree
