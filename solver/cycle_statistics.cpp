#include "solver/cycle_statistics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hemotree {

CycleStatistics::CycleStatistics(std::size_t vessels)
    : flow_(vessels, 0.0), pressure_(vessels, 0.0),
      p_min_(vessels, std::numeric_limits<double>::infinity()),
      p_max_(vessels, -std::numeric_limits<double>::infinity()) {}

void CycleStatistics::sample(const PulseSolver& solver, double dt) {
  // Rectangle rule over the steps: second order is not needed for means over thousands.
  for (std::size_t v = 0; v < flow_.size(); ++v) {
    const double p = solver.pressure_at(v, 0.5);
    flow_[v] += dt * solver.mean_flow(v);
    pressure_[v] += dt * p;
    p_min_[v] = std::min(p_min_[v], p);
    p_max_[v] = std::max(p_max_[v], p);
  }
  duration_ += dt;
}

std::vector<VesselCycle> CycleStatistics::close() {
  std::vector<VesselCycle> out(flow_.size());
  for (std::size_t v = 0; v < out.size(); ++v) {
    out[v] = {flow_[v] / duration_, pressure_[v] / duration_, p_max_[v], p_min_[v]};
    flow_[v] = pressure_[v] = 0;
    p_min_[v] = std::numeric_limits<double>::infinity();
    p_max_[v] = -std::numeric_limits<double>::infinity();
  }
  duration_ = 0;
  return out;
}

PeriodicityChange cycle_change(const std::vector<VesselCycle>& previous,
                               const std::vector<VesselCycle>& current) {
  PeriodicityChange worst;
  for (std::size_t v = 0; v < current.size(); ++v) {
    const double change = std::abs(current[v].mean_pressure - previous[v].mean_pressure) /
                          std::abs(current[v].mean_pressure);
    if (change > worst.change) worst = {change, v};
  }
  return worst;
}

}  // namespace hemotree
