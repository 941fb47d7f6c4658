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

#include "physics/blood.hpp"

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
    // The 4-point Lagrange interpolant on nodes k-1 .. k+2 as a cubic in t (Horner): three
    // multiply-adds, where the Lagrange weights took a dozen products.
    const double* c = &table_[4 * (octave * intervals + k)];
    return ((c[3] * t + c[2]) * t + c[1]) * t + c[0];
  }

 private:
  static constexpr std::size_t intervals = 512;  // per octave of the area
  static constexpr std::uint64_t mantissa_mask = (std::uint64_t{1} << 52) - 1;
  static constexpr std::uint64_t one_bits = std::uint64_t{1023} << 52;  // the bits of 1.0
  double below_table(double area) const;  // the law itself (collapsing lumens); NaN outside its domain

  Blood blood_;
  bool constant_ = false;
  double value_ = 0;  // constant: Newtonian, or Pries above its threshold
  double area_min_ = 0, area_max_ = 0;
  std::uint64_t first_exponent_bits_ = 0;  // the biased exponent of the first octave
  // Per octave and interval, the four coefficients of its cubic (from the law at the nodes
  // m = 1 + (j - 1) / N, j = k .. k + 3, of its own octave: every stencil stays inside it).
  std::vector<double> table_;
};

}  // namespace hemotree
