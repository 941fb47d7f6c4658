#include "steady/vessel_laws.hpp"

#include <cmath>
#include <numbers>
#include <string>

#include "core/errors.hpp"
#include "physics/wall_law.hpp"

namespace hemotree {

std::vector<TubeLaw> vessel_laws(const Network& net, const Blood& blood, double external_pressure,
                                 double thick_wall_ratio) {
  const std::size_t n = net.vessel_count();
  std::vector<TubeLaw> laws(n);
  for (std::size_t v = 0; v < n; ++v) {
    TubeLaw& law = laws[v];
    law.density = blood.density;
    law.alpha = blood.momentum_alpha();
    if (!net.beta.empty() && !std::isnan(net.beta[v])) {
      law.beta = net.beta[v];
      law.reference_area = std::numbers::pi / 4 * net.diameter[v] * net.diameter[v];
      law.reference_pressure = net.reference_pressure[v];
    } else {
      if (std::isnan(net.wall_thickness[v]) || std::isnan(net.youngs_modulus[v]))
        throw InputError("vessel " + std::to_string(net.id[v]) +
                         ": needs wall_thickness and youngs_modulus (or beta and reference_pressure)");
      const TubeLaw t = tube_law({net.diameter[v], net.wall_thickness[v], net.youngs_modulus[v]}, external_pressure,
                                 thick_wall_ratio);
      law.beta = t.beta;
      law.reference_area = t.reference_area;
      law.reference_pressure = t.reference_pressure;
    }
  }
  return laws;
}

}  // namespace hemotree
