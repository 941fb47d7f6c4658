// How a pulsatile run ended, what summary.json says of it and the exit status that goes with
// it: the one table of that contract (docs/reliability.md, "Exit status"; tested for each
// outcome in tests/cli/hemosolve_reliability.sh).
//
//   outcome        summary.json "status"   exit   results
//   complete       "complete"              0      the last cycle, trusted
//   not_periodic   "not periodic"          3      the last cycle, which --until-periodic's
//                                                 tolerance did not reach in --max-cycles
//   failed         "failed"                2      written, but wrong (mass lost, a forced step,
//                                                 a boundary flow the step cannot follow)
//   broken_down    "broken down"           2      the last whole cycle's, if any
//   interrupted    "interrupted"           128 + signal (130 SIGINT, 143 SIGTERM, 129 SIGHUP)
//
// Every outcome but complete exits non-zero, so that `hemosolve ... && next` never goes on
// from results that are not what was asked for; not periodic has its own status (3) because
// its numbers are a finished cycle's, which a script may still want to read.
#pragma once

namespace hemotree {

enum class RunOutcome { complete, not_periodic, failed, broken_down, interrupted };

// The word summary.json's "status" holds.
const char* to_string(RunOutcome outcome);

// The process's exit status; signal: the one that interrupted the run (interrupted only).
int exit_status(RunOutcome outcome, int signal = 0);

}  // namespace hemotree
