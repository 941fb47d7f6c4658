// What a caller says of a run's outcome (solver/run_outcome.hpp) beyond its exit status: the
// error of a run without trusted results, the warning of one whose results are not those
// asked for. Settings are named in the caller's words (RunConfiguration::words).
#pragma once

#include <string>

#include "solver/pulsatile_call.hpp"

namespace hemotree {

// broken down: the breakdown; failed: what is wrong with the results written; "" otherwise.
std::string outcome_error(const RunResult& result);

// interrupted: where the results and the checkpoint are, and how to continue; not periodic:
// the last cycle's change against the tolerance, and the exit status; "" otherwise.
// signal_name: the interrupting signal's ("SIGINT").
std::string outcome_warning(const RunResult& result, const RunConfiguration& config, const std::string& signal_name);

}  // namespace hemotree
