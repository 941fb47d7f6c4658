#include "physics/viscosity_table.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "physics/rheology.hpp"

namespace hemotree {

namespace {
constexpr double table_min_diameter = 2e-6;  // below: the law itself (collapsing lumens)
constexpr int table_points = 4096;
}  // namespace

ViscosityTable::ViscosityTable(const Blood& blood) : blood_(blood) {
  if (blood.rheology == Rheology::newtonian) {
    constant_ = true;
    value_ = blood.newtonian_viscosity;
    return;
  }
  value_ = apparent_viscosity(blood, blood.pries_max_diameter);
  log_d_min_ = std::log(table_min_diameter);
  log_d_max_ = std::log(blood.pries_max_diameter);
  // Two extra nodes at each end keep the 4-point stencil inside the table.
  step_ = (log_d_max_ - log_d_min_) / (table_points - 1);
  table_.resize(table_points + 4);
  // The law itself (not clamped at the threshold) so the stencil never straddles a kink.
  for (int k = 0; k < table_points + 4; ++k)
    table_[static_cast<std::size_t>(k)] =
        blood.plasma_viscosity *
        pries_relative_viscosity(std::exp(log_d_min_ + (k - 2) * step_), blood.hematocrit);
}

double ViscosityTable::below_table(double log_d) const { return apparent_viscosity(blood_, std::exp(log_d)); }

}  // namespace hemotree
