#include "solver/run_estimate.hpp"

#include <cmath>
#include <cstdio>

#include "pulse/step_cost.hpp"

namespace hemotree {

RunEstimate estimate_run(const std::vector<double>& elements_of_degree, double steps, int threads, double substeps,
                         double lumped_vessels, double spread_solves, double spread_nodes) {
  double substep = step_cost::per_step;
  for (std::size_t p = 0; p < elements_of_degree.size(); ++p)
    substep += elements_of_degree[p] * step_cost::element_step_seconds(static_cast<int>(p));
  // Two threads gave 1.8 times one thread's speed from 5000 vessels up (bench/README.md).
  const double speedup = threads > 1 ? 0.9 * threads : 1.0;
  const double spread = spread_solves * (step_cost::per_spread_solve + spread_nodes * step_cost::per_spread_node);
  return {steps, steps * (substeps * substep + lumped_vessels * step_cost::per_lumped_vessel) / speedup + steps * spread};
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

std::string describe_bytes(double bytes) {
  char text[64];
  if (bytes < 1e6) std::snprintf(text, sizeof text, "%.3g kB", bytes / 1e3);
  else if (bytes < 1e9) std::snprintf(text, sizeof text, "%.3g MB", bytes / 1e6);
  else std::snprintf(text, sizeof text, "%.3g GB", bytes / 1e9);
  return text;
}

}  // namespace hemotree
