#include "physics/blood.hpp"

#include <cmath>

namespace hemotree {

double Blood::pries_diameter_scale() const { return std::cbrt(human_mean_cell_volume / mean_cell_volume); }
double Blood::phase_separation_diameter_scale() const {
  return std::cbrt(phase_separation_mean_cell_volume / mean_cell_volume);
}

std::string_view to_string(Rheology rheology) {
  return rheology == Rheology::pries ? "pries" : "newtonian";
}

std::optional<Rheology> rheology_of(std::string_view name) {
  for (const Rheology r : {Rheology::pries, Rheology::newtonian})
    if (name == to_string(r)) return r;
  return std::nullopt;
}

}  // namespace hemotree
