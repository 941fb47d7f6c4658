// The apparent viscosity as a function of lumen area, fast enough to evaluate at every
// quadrature point of every step: the Pries law for the run's hematocrit is tabulated once
// on a uniform grid in log D and interpolated with 4-point Lagrange polynomials (relative
// error below 1e-9 against the law, 1.8e-10 measured). Evaluating the law directly costs three
// exponentials and two powers a point: more than half of a solver step (measured).
#pragma once

#include <vector>

#include "formats/boundary_conditions.hpp"

namespace hemotree {

class ViscosityTable {
 public:
  explicit ViscosityTable(const Blood& blood);
  // mu [Pa s] in a lumen of area A [m^2].
  double operator()(double area) const;

 private:
  Blood blood_;
  bool constant_ = false;
  double value_ = 0;                 // constant: Newtonian, or Pries above its threshold
  double log_d_min_ = 0, log_d_max_ = 0, step_ = 0;
  std::vector<double> table_;        // mu at log D = log_d_min_ + k step_
};

}  // namespace hemotree
