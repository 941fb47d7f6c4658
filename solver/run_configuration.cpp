#include "solver/run_configuration.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <initializer_list>
#include <string>
#include <utility>

#include "core/units.hpp"
#include "core/errors.hpp"
#include "core/setting_error.hpp"
#include "formats/quoting.hpp"

namespace hemotree {

namespace {

constexpr double most_steps_per_cycle = 1e12;  // beyond any machine's reach, and size_t's range is safe

// setting's value within [low, high]; said names the setting as the message does.
void check_count(long long value, long long low, long long high, const std::string& setting,
                 const std::string& said = {}) {
  if (value < low || value > high)
    throw SettingError(setting, (said.empty() ? placeholder(setting) : said) + " must lie in [" + std::to_string(low) +
                                    ", " + std::to_string(high) + "] (got " + std::to_string(value) + ")");
}

void check_range(double value, const Interval& range, const std::string& setting, const std::string& said = {}) {
  if (!range.contains(value))
    throw SettingError(setting, (said.empty() ? placeholder(setting) : said) + " must lie in " + describe(range, "") +
                                    " (got " + format_rounded(value) + ")");
}

}  // namespace

namespace {
// A caller's text as a message shows it: as written, unless it holds a control character
// (which a one-line message, and a placeholder's marks, must not carry).
std::string shown(const std::string& text) {
  const bool control = std::any_of(text.begin(), text.end(), [](char c) {
    return static_cast<unsigned char>(c) < 0x20 || c == 0x7f;
  });
  return control ? printable(text) : text;
}

[[noreturn]] void refuse_choice(const char* setting, const char* choices, const std::string& name) {
  throw SettingError(setting, placeholder(setting) + " must be " + choices + " (got '" + shown(name) + "')");
}

// Each choice's words, once: to_string and the *_named parsers below read the same table.
template <class Choice>
using ChoiceNames = std::initializer_list<std::pair<Choice, const char*>>;
constexpr ChoiceNames<TimeScheme> scheme_names = {
    {TimeScheme::exponential_ab2, "etd2"}, {TimeScheme::adams_bashforth2, "ab2"}, {TimeScheme::runge_kutta4, "rk4"}};
constexpr ChoiceNames<ModelChoice> model_names = {
    {ModelChoice::automatic, "auto"}, {ModelChoice::one_d, "1d"}, {ModelChoice::zero_d, "0d"}};
constexpr ChoiceNames<RedCells> red_cell_names = {{RedCells::fixed, "fixed"}, {RedCells::transport, "transport"}};
constexpr ChoiceNames<StartChoice> start_names = {
    {StartChoice::steady, "steady"}, {StartChoice::rest, "rest"}, {StartChoice::periodic, "periodic"}};
constexpr ChoiceNames<Rheology> rheology_names = {{Rheology::pries, "pries"}, {Rheology::newtonian, "newtonian"}};
constexpr ChoiceNames<ResultsFormat> results_format_names = {{ResultsFormat::text, "text"}, {ResultsFormat::hdf5, "h5"}};

template <class Choice>
const char* name_of(Choice choice, ChoiceNames<Choice> names) {
  for (const auto& [c, name] : names)
    if (c == choice) return name;
  return names.begin()->second;
}

// The choice a text names; SettingError listing the choices ("etd2, ab2 or rk4") otherwise.
template <class Choice>
Choice named(const std::string& text, ChoiceNames<Choice> names, const char* setting) {
  for (const auto& [choice, name] : names)
    if (text == name) return choice;
  std::string choices;
  for (std::size_t i = 0; i < names.size(); ++i)
    choices += std::string(i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names.begin()[i].second;
  refuse_choice(setting, choices.c_str(), text);
}
}  // namespace

const char* to_string(RedCells cells) { return name_of(cells, red_cell_names); }
const char* to_string(ModelChoice model) { return name_of(model, model_names); }
const char* to_string(TimeScheme scheme) { return name_of(scheme, scheme_names); }
const char* to_string(StartChoice start) { return name_of(start, start_names); }
const char* to_string(ResultsFormat format) { return name_of(format, results_format_names); }

TimeScheme time_scheme_named(const std::string& name) { return named(name, scheme_names, "scheme"); }

ModelChoice model_named(const std::string& name) { return named(name, model_names, "model"); }

StartChoice start_named(const std::string& name) { return named(name, start_names, "start"); }

ResultsFormat results_format_named(const std::string& name) { return named(name, results_format_names, "format"); }

Rheology rheology_named(const std::string& name) { return named(name, rheology_names, "rheology"); }

namespace {
// "auto" (SolverOptions::automatic) or a whole number in [low, high].
int automatic_or_count(const std::string& name, int low, int high, const char* setting) {
  if (name == "auto") return SolverOptions::automatic;
  std::size_t used = 0;
  int count = -1;
  try {
    count = std::stoi(name, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != name.size() || count < low || count > high)
    refuse_choice(setting,
                  ("auto or a whole number in [" + std::to_string(low) + ", " + std::to_string(high) + "]").c_str(), name);
  return count;
}
}  // namespace

int degree_named(const std::string& name) { return automatic_or_count(name, 0, 30, "degree"); }

int settling_degree_named(const std::string& name) { return automatic_or_count(name, 0, 30, "settling_degree"); }

int coupling_passes_named(const std::string& name) { return automatic_or_count(name, 1, 10, "coupling_passes"); }

double lumped_step_named(const std::string& name) {
  if (name == "auto") return 0;
  std::size_t used = 0;
  double fraction = 0;
  try {
    fraction = std::stod(name, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != name.size() || !(fraction > 0 && fraction <= 0.1))
    refuse_choice("lumped_step", "auto or a fraction of the period in (0, 0.1]", name);
  return fraction;
}

RedCells red_cells_named(const std::string& name) { return named(name, red_cell_names, "red_cells"); }

// In the order hemosolve has always checked them, so that its first complaint is the same.
SolverOptions solver_options(const RunConfiguration& config) {
  SolverOptions options = config.solver;
  if (config.carries_transport()) options.lumped_sections = 1;
  return options;
}

void check_configuration(const RunConfiguration& c) {
  check_count(c.cycles, 1, 100000, "cycles");
  check_count(c.max_cycles, 1, 100000, "max_cycles");
  check_count(c.settling_step, 0, 20, "settling_step");
  if (c.settling_degree != SolverOptions::automatic) check_count(c.settling_degree, 0, 30, "settling_degree");
  check_count(c.checkpoint_every, 0, 100000, "checkpoint_every");
  check_count(c.frames, 0, 10000, "frames");
  check_count(c.solver.periodic_harmonics, 1, 1000, "periodic_harmonics");
  if (c.until_periodic) check_range(c.periodic_tolerance, {0, 1, true, true}, "periodic_tolerance");
  const SolverOptions& s = c.solver;
  check_range(s.lumped_transit, {0, 1}, "lumped_transit");
  check_range(s.lumped_rc, {0, INFINITY}, "lumped_rc");
  check_count(s.lumped_sections, 1, 64, "lumped_sections");
  if (s.lumped_step != 0) check_range(s.lumped_step, {0, 0.1, true, false}, "lumped_step");  // 0: automatic
  if (s.coupling_passes != SolverOptions::automatic) check_count(s.coupling_passes, 1, 10, "coupling_passes");
  check_count(s.lumped_passes, 1, 10, "lumped_passes");
  check_range(s.cfl, {0, c.force ? 100.0 : 1.0, true, false}, "cfl",
              c.force ? placeholder("cfl") + " (with " + placeholder("force") + ")" : placeholder("cfl"));
  if (s.degree != SolverOptions::automatic) check_count(s.degree, 0, 30, "degree");
  check_count(s.degree_rule.low, 0, 30, "low_degree");
  check_count(s.degree_rule.raise_to, 0, 30, "raise_degree");
  check_count(s.degree_rule.high, 0, 30, "high_degree");
  check_range(s.degree_rule.linear_error, {0, INFINITY}, "linear_error");  // inf: never degree 2
  check_count(s.elements, 1, 1000, "elements");
  check_range(s.thick_wall_ratio, {0, 10, true, false}, "thick_wall_ratio");
  if (!(c.transport_step > 0 && c.transport_step <= 0.5))
    throw SettingError("transport_step", placeholder("transport_step") + " " + format_rounded(c.transport_step) +
                                             ": accepted range (0, 0.5] of the period");
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
  // Named by placeholders: worded by the caller's words where kept, by the catcher's where thrown.
  std::string beyond_limit;
  if (asked > 0 && asked > solver.stable_dt() * (1 + 1e-9))
    beyond_limit = placeholder("dt") + " " + format_quantity(asked, "s") + " is " +
                   format_rounded(asked / solver.stable_dt()) + " times the " +
                   (solver.lumped_vessels_in_run() > 0 ? "0D step's accuracy limit " : "stability limit ") +
                   format_quantity(solver.stable_dt(), "s") + " (" + solver.stable_dt_reason() + ")";
  if (!beyond_limit.empty() && !config.force)
    throw SettingError("dt", beyond_limit + "; the solution would blow up or be wrong: use a " + placeholder("dt") +
                                 " of at most the limit, or " + placeholder("force") + " to run it anyway");
  d.beyond_limit = in_words(beyond_limit, config.words);
  d.reason = in_words(solver.dt_reason(), config.words);
  d.cycle = decide_cycle_step(period, solver.dt(), d.reason);
  solver.set_time_step(d.cycle.dt);  // slightly smaller, so that cycles end exactly on a step
  return d;
}

}  // namespace hemotree
