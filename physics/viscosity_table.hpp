// The apparent viscosity as a function of lumen area, fast enough to evaluate at every
// quadrature point of every step: the Pries law for the run's hematocrit is tabulated once
// on a uniform grid in log D and interpolated with 4-point Lagrange polynomials (relative
// error below 1e-9 against the law, 1.8e-10 measured), inline in the solver's loops. Evaluating the law directly costs three
// exponentials and two powers a point: more than half of a solver step (measured).
#pragma once

#include <cmath>
#include <numbers>
#include <vector>

#include "formats/boundary_conditions.hpp"

namespace hemotree {

class ViscosityTable {
 public:
  explicit ViscosityTable(const Blood& blood);
  // mu [Pa s] in a lumen of area A [m^2].
  double operator()(double area) const {
    if (constant_) return value_;
    const double log_d = 0.5 * std::log(4 / std::numbers::pi * area);
    if (log_d >= log_d_max_) return value_;
    if (log_d < log_d_min_) return below_table(log_d);
    // 4-point Lagrange interpolation on nodes k-1, k, k+1, k+2 around s = k + t.
    const double s = (log_d - log_d_min_) / step_;
    const auto k = static_cast<std::size_t>(s);
    const double t = s - static_cast<double>(k);
    const double* f = &table_[k + 1];  // f[0..3] = nodes k-1 .. k+2 (table offset by 2)
    const double w0 = -t * (t - 1) * (t - 2) / 6, w1 = (t + 1) * (t - 1) * (t - 2) / 2;
    const double w2 = -(t + 1) * t * (t - 2) / 2, w3 = (t + 1) * t * (t - 1) / 6;
    return w0 * f[0] + w1 * f[1] + w2 * f[2] + w3 * f[3];
  }

 private:
  double below_table(double log_d) const;  // the law itself (collapsing lumens)

  Blood blood_;
  bool constant_ = false;
  double value_ = 0;                 // constant: Newtonian, or Pries above its threshold
  double log_d_min_ = 0, log_d_max_ = 0, step_ = 0;
  std::vector<double> table_;        // mu at log D = log_d_min_ + k step_
};

}  // namespace hemotree
