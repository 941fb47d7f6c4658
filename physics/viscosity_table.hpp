// The apparent viscosity as a function of lumen area, fast enough to evaluate at every
// quadrature point of every step and three times per 0D vessel and step: the Pries law for
// the run's hematocrit is tabulated once and interpolated with 4-point Lagrange polynomials
// (relative error below 1e-9 against the law), inline in the solver's loops. Evaluating the
// law directly costs three exponentials and two powers a point: more than half of a solver
// step (measured).
//
// The grid is geometric across octaves of the area and uniform within each, so that the
// area's own binary exponent and mantissa are the table's index: no logarithm (a uniform
// grid in log D needed one, a fifth of a full tree's step).
#pragma once

#include <bit>
#include <cstdint>
#include <vector>

#include "formats/boundary_conditions.hpp"

namespace hemotree {

class ViscosityTable {
 public:
  explicit ViscosityTable(const Blood& blood);
  // mu [Pa s] in a lumen of area A [m^2].
  double operator()(double area) const {
    if (constant_) return value_;
    if (area >= area_max_) return value_;
    if (!(area >= area_min_)) return below_table(area);
    // area = 2^e m, m in [1, 2): octave e - e_min, position (m - 1) N within it.
    const auto bits = std::bit_cast<std::uint64_t>(area);
    const auto octave = static_cast<std::size_t>((bits >> 52) - first_exponent_bits_);
    const double m = std::bit_cast<double>((bits & mantissa_mask) | one_bits);
    const double s = (m - 1) * intervals;
    const auto k = static_cast<std::size_t>(s);
    const double t = s - static_cast<double>(k);
    // 4-point Lagrange interpolation on nodes k-1, k, k+1, k+2 around s = k + t.
    const double* f = &table_[octave * (intervals + 3) + k];  // f[0..3] = nodes k-1 .. k+2
    const double w0 = -t * (t - 1) * (t - 2) / 6, w1 = (t + 1) * (t - 1) * (t - 2) / 2;
    const double w2 = -(t + 1) * t * (t - 2) / 2, w3 = (t + 1) * t * (t - 1) / 6;
    return w0 * f[0] + w1 * f[1] + w2 * f[2] + w3 * f[3];
  }

 private:
  static constexpr std::size_t intervals = 512;  // per octave of the area
  static constexpr std::uint64_t mantissa_mask = (std::uint64_t{1} << 52) - 1;
  static constexpr std::uint64_t one_bits = std::uint64_t{1023} << 52;  // the bits of 1.0
  double below_table(double area) const;  // the law itself (collapsing lumens)

  Blood blood_;
  bool constant_ = false;
  double value_ = 0;  // constant: Newtonian, or Pries above its threshold
  double area_min_ = 0, area_max_ = 0;
  std::uint64_t first_exponent_bits_ = 0;  // the biased exponent of the first octave
  // Per octave, N + 3 nodes: m = 1 + (j - 1) / N for j = 0 .. N + 2 (one before the octave,
  // two after it, so that every stencil stays inside its own octave's row).
  std::vector<double> table_;
};

}  // namespace hemotree
