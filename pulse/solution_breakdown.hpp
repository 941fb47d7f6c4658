// The solution stopped making sense (A <= 0, NaN): what the user needs to act on it.
#pragma once

#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>

namespace hemotree {

struct SolutionBreakdown : std::runtime_error {
  SolutionBreakdown(std::int64_t vessel_id, double time)
      : std::runtime_error(message(vessel_id, time)), vessel(vessel_id), at(time) {}
  std::int64_t vessel;
  double at;

 private:
  static std::string message(std::int64_t vessel_id, double time) {
    std::ostringstream m;
    m << "the solution broke down in vessel " << vessel_id << " at t = " << time
      << " s (area not positive or not finite); try a smaller time step (--dt or --cfl) or a "
         "lower degree (--degree)";
    return m.str();
  }
};

}  // namespace hemotree
