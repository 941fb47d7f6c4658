#include "solver/run_configuration.hpp"

#include <cmath>

#include "core/units.hpp"
#include "core/errors.hpp"

namespace hemotree {

namespace {

constexpr double most_steps_per_cycle = 1e12;  // beyond any machine's reach, and size_t's range is safe

void check_count(long long value, long long low, long long high, const std::string& name) {
  if (value < low || value > high)
    throw InputError(name + " must lie in [" + std::to_string(low) + ", " + std::to_string(high) + "] (got " +
                     std::to_string(value) + ")");
}

void check_range(double value, const Interval& range, const std::string& name) {
  if (!range.contains(value))
    throw InputError(name + " must lie in " + describe(range, "") + " (got " + format_rounded(value) + ")");
}

}  // namespace

const char* to_string(RedCells cells) { return cells == RedCells::transport ? "transport" : "fixed"; }

const char* to_string(ModelChoice model) {
  switch (model) {
    case ModelChoice::automatic: return "auto";
    case ModelChoice::one_d: return "1d";
    case ModelChoice::zero_d: return "0d";
  }
  return "auto";
}

const char* to_string(TimeScheme scheme) {
  switch (scheme) {
    case TimeScheme::exponential_ab2: return "etd2";
    case TimeScheme::adams_bashforth2: return "ab2";
    case TimeScheme::runge_kutta4: return "rk4";
  }
  return "etd2";
}

// In the order hemosolve has always checked them, so that its first complaint is the same.
void check_configuration(const RunConfiguration& c) {
  check_count(c.cycles, 1, 100000, "--cycles");
  check_count(c.max_cycles, 1, 100000, "--max-cycles");
  check_count(c.checkpoint_every, 0, 100000, "--checkpoint-every");
  check_count(c.frames, 0, 10000, "--frames");
  if (c.until_periodic) check_range(c.periodic_tolerance, {0, 1, true, true}, "--until-periodic");
  const SolverOptions& s = c.solver;
  check_range(s.lumped_transit, {0, 1}, "--lumped-transit");
  check_range(s.lumped_rc, {0, INFINITY}, "--lumped-rc");
  check_range(s.lumped_step, {0, 0.1, true, false}, "--lumped-step");
  check_count(s.lumped_passes, 1, 10, "--lumped-passes");
  check_range(s.cfl, {0, c.force ? 100.0 : 1.0, true, false}, c.force ? "--cfl (with --force)" : "--cfl");
  if (s.degree != SolverOptions::automatic) check_count(s.degree, 0, 30, "--degree");
  check_count(s.degree_rule.low, 0, 30, "--low-degree");
  check_count(s.degree_rule.raise_to, 0, 30, "--raise-degree");
  check_count(s.degree_rule.high, 0, 30, "--high-degree");
  check_range(s.degree_rule.linear_error, {0, INFINITY}, "--linear-error");  // inf: never degree 2
  check_count(s.elements, 1, 1000, "--elements");
  check_range(s.thick_wall_ratio, {0, 10, true, false}, "--thick-wall-ratio");
  if (!(c.transport_step > 0 && c.transport_step <= 0.5))
    throw InputError("--transport-step " + format_rounded(c.transport_step) + ": accepted range (0, 0.5] of the period");
}

CycleStep decide_cycle_step(double period, double step, const std::string& reason) {
  const double steps_wanted = std::ceil(period / step - 1e-9);
  if (!(steps_wanted <= most_steps_per_cycle))
    throw InputError("a time step of " + format_quantity(step, "s") + " (" + reason + ") needs " +
                     format_rounded(steps_wanted) + " steps per cycle: no run can finish; check that vessel's "
                     "wall and length, and the inlet's flow");
  CycleStep cycle;
  cycle.steps_per_cycle = static_cast<std::size_t>(steps_wanted);
  cycle.dt = period / static_cast<double>(cycle.steps_per_cycle);  // a whole number per cycle
  return cycle;
}

TimeStepDecision decide_time_step(PulseSolver& solver, const RunConfiguration& config, double period) {
  const double asked = config.solver.dt;
  TimeStepDecision d;
  if (asked > 0 && asked > solver.stable_dt() * (1 + 1e-9))
    d.beyond_limit = "--dt " + format_quantity(asked, "s") + " is " + format_rounded(asked / solver.stable_dt()) +
                     " times the " + (solver.lumped_count() > 0 ? "0D step's accuracy limit " : "stability limit ") +
                     format_quantity(solver.stable_dt(), "s") + " (" + in_words(solver.stable_dt_reason(), config.words) + ")";
  if (!d.beyond_limit.empty() && !config.force)
    throw InputError(d.beyond_limit + "; the solution would blow up or be wrong: use a --dt of at most the limit, or "
                     "--force to run it anyway");
  d.reason = in_words(solver.dt_reason(), config.words);
  d.cycle = decide_cycle_step(period, solver.dt(), d.reason);
  solver.set_time_step(d.cycle.dt);  // slightly smaller, so that cycles end exactly on a step
  return d;
}

}  // namespace hemotree
