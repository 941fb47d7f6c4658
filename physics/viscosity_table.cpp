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

double ViscosityTable::operator()(double area) const {
  if (constant_) return value_;
  const double log_d = 0.5 * std::log(4 * area / std::numbers::pi);
  if (log_d >= log_d_max_) return value_;
  if (log_d < log_d_min_) return apparent_viscosity(blood_, std::exp(log_d));
  // 4-point Lagrange interpolation on nodes k-1, k, k+1, k+2 around s = k + t.
  const double s = (log_d - log_d_min_) / step_;
  const auto k = static_cast<std::size_t>(s);
  const double t = s - static_cast<double>(k);
  const double* f = &table_[k + 1];  // f[0..3] = nodes k-1 .. k+2 (table offset by 2)
  const double w0 = -t * (t - 1) * (t - 2) / 6, w1 = (t + 1) * (t - 1) * (t - 2) / 2;
  const double w2 = -(t + 1) * t * (t - 2) / 2, w3 = (t + 1) * t * (t - 1) / 6;
  return w0 * f[0] + w1 * f[1] + w2 * f[2] + w3 * f[3];
}

}  // namespace hemotree
