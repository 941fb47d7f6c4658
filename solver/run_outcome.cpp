#include "solver/run_outcome.hpp"

namespace hemotree {

const char* to_string(RunOutcome outcome) {
  switch (outcome) {
    case RunOutcome::complete: return "complete";
    case RunOutcome::not_periodic: return "not periodic";
    case RunOutcome::failed: return "failed";
    case RunOutcome::broken_down: return "broken down";
    case RunOutcome::interrupted: return "interrupted";
  }
  return "failed";
}

int exit_status(RunOutcome outcome, int signal) {
  switch (outcome) {
    case RunOutcome::complete: return 0;
    case RunOutcome::not_periodic: return 3;
    case RunOutcome::failed:
    case RunOutcome::broken_down: return 2;
    case RunOutcome::interrupted: return 128 + signal;
  }
  return 2;
}

}  // namespace hemotree
