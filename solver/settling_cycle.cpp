#include "solver/settling_cycle.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <utility>
#include <vector>

#include "solver/cycle_over_ranks.hpp"
#include "solver/cycle_statistics.hpp"
#include "solver/decisions_over_ranks.hpp"
#include "solver/run_estimate.hpp"

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
  // Over ranks every decision is every rank's (solver/decisions_over_ranks.hpp).
  const bool over_ranks = solver.over_ranks();
  for (std::size_t k = 0; k < steps; ++k) {
    solver.step();
    stats.sample(solver, solver.time(), solver.time() - sampled_until);
    sampled_until = solver.time();
    if (k % 256 == 0) {
      s.signal = over_ranks ? interrupt_on_any_rank(observer.poll_interrupt()) : observer.poll_interrupt();
      if (s.signal != 0) return s;
    }
  }
  if (over_ranks) check_solution_on_every_rank(solver);
  else solver.check_solution();
  solver.release_step_arrays();
  // The rest freed here; the balance is the lead's, which alone takes every vessel's mean
  // pressure (over ranks a block at a time from the rank that steps it).
  const CycleSummary own = stats.close(solver);
  std::vector<double> mean_pressure =
      over_ranks ? gather_mean_pressures(net, solver, own, stats.entry_vessels(solver)) : mean_pressures(own.vessels);
  solver.balance_compliances(period, std::move(mean_pressure));
  solver.set_time_step(run_step);
  solver.set_coupling_passes(run_passes);
  solver.restart_clock();
  s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return s;
}

namespace {

// A cycle's cost by the estimate's model (solver/run_estimate.hpp), on one thread.
double estimated_cycle(const Network& net, const PulseSolver& solver, double period) {
  std::vector<double> elements_of_degree(static_cast<std::size_t>(solver.max_degree()) + 1, 0.0);
  for (std::size_t v = 0; v < net.vessel_count(); ++v)
    if (!solver.is_lumped(v)) elements_of_degree[static_cast<std::size_t>(solver.degree(v))] += solver.elements_per_vessel();
  return estimate_run(elements_of_degree, std::ceil(period / solver.dt()), 1, solver.substeps() * solver.coupling_passes(),
                      static_cast<double>(solver.lumped_vessels_in_run()))
      .seconds;
}

}  // namespace

// Automatic: degree 2 where most of the vessels are 1D (the large arteries, whose pulse is
// nonlinear enough that the linear start leaves its first cycle 2e-3 off; the complement of
// the 0D settling cycle's rule) and the settling cycle costs at most a third of one. Measured
// (docs/solver.md §6a): ADAN56 and the circle of Willis periodic to 1e-3 in two cycles after
// it, three without; the trees, mostly 0D, in two without it.
std::unique_ptr<PulseSolver> low_degree_settling_solver(const Network& net, const PulseSolver& run,
                                                       const RunConfiguration& config, double period,
                                                       const PulseRanks* ranks) {
  const bool automatic = config.settling_degree == SolverOptions::automatic;
  const int degree = automatic ? 2 : config.settling_degree;
  if (!(config.until_periodic && degree > 0 && config.balance_compliances && run.started_from_steady() &&
        run.lumped_vessels_in_run() < net.vessel_count() && degree < run.max_degree()))
    return nullptr;
  if (automatic && 2 * run.lumped_vessels_in_run() >= net.vessel_count()) return nullptr;
  SolverOptions options = solver_options(config);
  options.dt = 0;  // its own stable step
  if (options.degree != SolverOptions::automatic) options.degree = std::min(options.degree, degree);
  options.degree_rule.low = std::min(options.degree_rule.low, degree);
  options.degree_rule.high = std::min(options.degree_rule.high, degree);
  options.degree_rule.raise_to = std::min(options.degree_rule.raise_to, degree);
  auto settling = std::make_unique<PulseSolver>(net, options, ranks);
  if (automatic && estimated_cycle(net, *settling, period) > estimated_cycle(net, run, period) / 3) return nullptr;
  return settling;
}

std::size_t low_degree_settling_steps(const PulseSolver& settling, double period, int settling_step) {
  return std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(period / settling.dt() - 1e-9)) *
                                      static_cast<std::size_t>(settling.coupling_passes()) /
                                      static_cast<std::size_t>(std::max(1, settling_step)));
}

}  // namespace hemotree
