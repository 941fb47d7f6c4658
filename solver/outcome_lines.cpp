#include "solver/outcome_lines.hpp"

#include "core/setting_error.hpp"
#include "core/units.hpp"

namespace hemotree {

namespace {
std::string plural(std::size_t count, const std::string& noun) {
  return std::to_string(count) + " " + noun + (count == 1 ? "" : "s");
}
}  // namespace

std::string outcome_error(const RunResult& result) {
  if (result.outcome == RunOutcome::broken_down) return result.error;
  if (result.outcome == RunOutcome::failed)
    return "the results are wrong and marked failed in summary.json: " + result.error;
  return {};
}

std::string outcome_warning(const RunResult& result, const RunConfiguration& config, const std::string& signal_name) {
  const auto named = [&](const char* setting) { return in_words(placeholder(setting), config.words); };
  const std::string& out_dir = config.out_dir;
  if (result.outcome == RunOutcome::interrupted)
    return "interrupted by " + signal_name + " after " + plural(static_cast<std::size_t>(result.cycles_done), "cycle") +
           ": " + out_dir +
           (result.cycles_done > 0 ? " holds the results of the last whole cycle and its checkpoint"
                                   : " holds the checkpoint of the start (no cycle was completed)") +
           "; " + named("resume") + " " + out_dir + " continues";
  if (result.outcome == RunOutcome::not_periodic)
    return "not periodic within " + std::to_string(config.max_cycles) + " cycles (" + named("max_cycles") + ")" +
           (result.has_change ? ": the last cycle changed by " + format_rounded(result.change) + " (vessel " +
                                    std::to_string(result.slowest_vessel) + ")"
                              : std::string()) +
           ", above " + named("periodic_tolerance") + " " + format_rounded(config.periodic_tolerance) +
           "; exit status " + std::to_string(exit_status(result.outcome));
  return {};
}

}  // namespace hemotree
