#include "solver/settling_cycle.hpp"

#include <chrono>
#include <utility>
#include <vector>

#include "solver/cycle_statistics.hpp"

namespace hemotree {

Settling settle(const Network& net, PulseSolver& solver, std::size_t steps, RunObserver& observer) {
  const auto started = std::chrono::steady_clock::now();
  Settling s;
  s.steps = steps;
  const double period = solver.period(), run_step = solver.dt();
  const int run_passes = solver.coupling_passes();
  solver.set_time_step(period / static_cast<double>(steps));
  solver.set_coupling_passes(1);
  solver.balance_compliances(period);  // the cycle's start
  CycleStatistics stats(net, solver, 1 / period);
  stats.begin(solver);
  double sampled_until = solver.time();
  for (std::size_t k = 0; k < steps; ++k) {
    solver.step();
    stats.sample(solver, solver.time(), solver.time() - sampled_until);
    sampled_until = solver.time();
    if (k % 256 == 0 && (s.signal = observer.poll_interrupt()) != 0) return s;
  }
  solver.check_solution();
  solver.release_step_arrays();
  std::vector<double> mean_pressure = mean_pressures(stats.close(solver).vessels);  // the rest freed here
  solver.balance_compliances(period, std::move(mean_pressure));
  solver.set_time_step(run_step);
  solver.set_coupling_passes(run_passes);
  solver.restart_clock();
  s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return s;
}

}  // namespace hemotree
