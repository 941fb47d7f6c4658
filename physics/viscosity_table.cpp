#include "physics/viscosity_table.hpp"

#include <cmath>
#include <limits>
#include <numbers>

#include "core/errors.hpp"
#include "physics/rheology.hpp"

namespace hemotree {

namespace {
constexpr double table_min_diameter = 2e-6;  // below: the law itself (collapsing lumens)
double diameter_of(double area) { return std::sqrt(4 / std::numbers::pi * area); }
}  // namespace

ViscosityTable::ViscosityTable(const Blood& blood) : blood_(blood) {
  if (blood.rheology == Rheology::newtonian) {
    constant_ = true;
    value_ = blood.newtonian_viscosity;
    return;
  }
  value_ = apparent_viscosity(blood, blood.pries_max_diameter);
  area_min_ = std::numbers::pi / 4 * table_min_diameter * table_min_diameter;
  area_max_ = std::numbers::pi / 4 * blood.pries_max_diameter * blood.pries_max_diameter;
  int first = 0, last = 0;
  std::frexp(area_min_, &first);  // area = f 2^e, f in [1/2, 1): the octave [2^(e-1), 2^e)
  std::frexp(area_max_, &last);
  first_exponent_bits_ = std::bit_cast<std::uint64_t>(std::ldexp(1.0, first - 1)) >> 52;
  const int octaves = last - first + 1;
  table_.resize(static_cast<std::size_t>(octaves) * intervals * 4);
  std::vector<double> f(intervals + 3);
  const double scale = blood.pries_diameter_scale();  // as apparent_viscosity
  for (int o = 0; o < octaves; ++o) {
    // Per octave, N + 3 nodes m = 1 + (j - 1) / N, j = 0 .. N + 2 (one before the octave, two
    // after it), the law itself (not clamped at the threshold) so that no stencil straddles
    // a kink.
    for (std::size_t j = 0; j < intervals + 3; ++j) {
      const double m = 1 + (static_cast<double>(j) - 1) / intervals;
      f[j] = blood.plasma_viscosity * pries_relative_viscosity(scale * diameter_of(std::ldexp(m, first - 1 + o)),
                                                                blood.hematocrit);
    }
    // Interval k, t in [0, 1) from node k + 1: the Lagrange weights of nodes k .. k + 3,
    // -t(t-1)(t-2)/6, (t+1)(t-1)(t-2)/2, -(t+1)t(t-2)/2, (t+1)t(t-1)/6, expanded in powers of t.
    for (std::size_t k = 0; k < intervals; ++k) {
      const double f0 = f[k], f1 = f[k + 1], f2 = f[k + 2], f3 = f[k + 3];
      double* c = &table_[4 * (static_cast<std::size_t>(o) * intervals + k)];
      c[0] = f1;
      c[1] = -f0 / 3 - f1 / 2 + f2 - f3 / 6;
      c[2] = f0 / 2 - f1 + f2 / 2;
      c[3] = (f3 - f0) / 6 + (f1 - f2) / 2;
    }
  }
}

double ViscosityTable::below_table(double area) const {
  // A lumen outside the law's domain (collapsed, or not a number once a solution has broken
  // down) gives NaN rather than the law's exception: this runs inside OpenMP regions, which no
  // exception may leave, and the solver's breakdown checks then name the vessel and the time.
  if (!(area > 0) || !std::isfinite(area)) return std::numeric_limits<double>::quiet_NaN();
  try {
    return apparent_viscosity(blood_, diameter_of(area));
  } catch (const InputError&) {
    return std::numeric_limits<double>::quiet_NaN();
  }
}

}  // namespace hemotree
