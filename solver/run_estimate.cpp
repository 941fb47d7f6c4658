#include "solver/run_estimate.hpp"

#include <cmath>
#include <cstdio>

namespace hemotree {

namespace {
// Measured on this project's machines (bench/README.md): the 5301-vessel network (2516, 2639
// and 146 elements of degree 1, 2 and 7) takes 2.5 ms a step on one core of the Intel Xeon
// VM (0.77 ms on the AMD EPYC one); the carotid (one element of degree 7) 10 us, nearly all
// of it per-step overhead. The slower machine sets the constants: an estimate that errs
// should err long. The run measures itself over its first steps too (pulsatile_run).
constexpr double step_cost = 10e-6;    // [s per step]
constexpr double fixed_cost = 300e-9;  // [s per element and step]
constexpr double modal_cost = 18e-9;   // [s per element, step and (p + 1)^2]
// 0D vessels: one linearisation, factorisation and two solves of the nodal system per step,
// and the cycle statistics' samples. Measured with two threads 42 ns a vessel and step on
// 1 M and 3.8 M vessels (bench/README.md, "The lean engine"), about 76 ns on one at two
// threads' 1.8-fold speed-up: 100 ns, so that the estimate errs long.
constexpr double lumped_cost = 100e-9;  // [s per 0D vessel and step]
}  // namespace

double element_step_seconds(int degree) {
  // Fitted to steps of one degree everywhere (bench/README.md, "Cost model"): a fixed part
  // per element (traces, Riemann problems, friction) and a part that grows with the modes
  // times the quadrature points of the degree's products.
  const double modes = degree + 1;
  return fixed_cost + modal_cost * modes * modes;
}

RunEstimate estimate_run(const std::vector<double>& elements_of_degree, double steps, int threads, double substeps,
                         double lumped_vessels) {
  double substep = step_cost;
  for (std::size_t p = 0; p < elements_of_degree.size(); ++p)
    substep += elements_of_degree[p] * element_step_seconds(static_cast<int>(p));
  // Two threads gave 1.8 times one thread's speed from 5000 vessels up (bench/README.md).
  const double speedup = threads > 1 ? 0.9 * threads : 1.0;
  return {steps, steps * (substeps * substep + lumped_vessels * lumped_cost) / speedup};
}

std::string describe_duration(double seconds) {
  char text[64];
  if (!std::isfinite(seconds)) return "forever";
  if (seconds < 120) std::snprintf(text, sizeof text, "%.3g s", seconds);
  else if (seconds < 7200) std::snprintf(text, sizeof text, "%.3g min", seconds / 60);
  else if (seconds < 2 * 86400) std::snprintf(text, sizeof text, "%.3g h", seconds / 3600);
  else if (seconds < 2 * 365.25 * 86400) std::snprintf(text, sizeof text, "%.3g days", seconds / 86400);
  else std::snprintf(text, sizeof text, "%.3g years", seconds / (365.25 * 86400));
  return text;
}

}  // namespace hemotree
