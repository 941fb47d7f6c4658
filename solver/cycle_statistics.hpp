// Per-vessel statistics over one cardiac cycle, sampled every time step at each vessel's
// centre: mean flow, mean, systolic and diastolic pressure, pulsatility index; and the
// cycle-to-cycle change that decides when the solution is periodic.
#pragma once

#include <cstdint>
#include <vector>

#include <nlohmann/json.hpp>

#include "solver/pulse_solver.hpp"

namespace hemotree {

struct VesselCycle {
  double mean_flow = 0, mean_pressure = 0;
  double systolic_pressure = 0, diastolic_pressure = 0;
  double pulsatility_index() const {
    return (systolic_pressure - diastolic_pressure) / mean_pressure;
  }
};

class CycleStatistics {
 public:
  explicit CycleStatistics(std::size_t vessels);
  void sample(const PulseSolver& solver, double dt);  // after a step of length dt
  // Closes the cycle: returns the statistics and starts the next cycle.
  std::vector<VesselCycle> close();

 private:
  std::vector<double> flow_, pressure_, p_min_, p_max_;
  double duration_ = 0;
};

// The largest relative change of a vessel's mean pressure between two cycles, and where.
struct PeriodicityChange {
  double change = 0;
  std::size_t vessel = 0;
};
PeriodicityChange cycle_change(const std::vector<VesselCycle>& previous,
                               const std::vector<VesselCycle>& current);

}  // namespace hemotree
