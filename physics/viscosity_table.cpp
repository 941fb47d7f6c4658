#include "physics/viscosity_table.hpp"

#include <cmath>
#include <numbers>

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
  table_.resize(static_cast<std::size_t>(octaves) * (intervals + 3));
  // The law itself (not clamped at the threshold) so the stencil never straddles a kink.
  for (int o = 0; o < octaves; ++o)
    for (std::size_t j = 0; j < intervals + 3; ++j) {
      const double m = 1 + (static_cast<double>(j) - 1) / intervals;
      const double area = std::ldexp(m, first - 1 + o);
      table_[static_cast<std::size_t>(o) * (intervals + 3) + j] =
          blood.plasma_viscosity * pries_relative_viscosity(diameter_of(area), blood.hematocrit);
    }
}

double ViscosityTable::below_table(double area) const { return apparent_viscosity(blood_, diameter_of(area)); }

}  // namespace hemotree
