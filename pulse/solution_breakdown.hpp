// The solution stopped making sense (A <= 0, NaN): what the user needs to act on it.
#pragma once

#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>

#include "core/setting_error.hpp"

namespace hemotree {

struct SolutionBreakdown : std::runtime_error {
  SolutionBreakdown(std::int64_t vessel_id, double time)
      : std::runtime_error(in_words(with_placeholders(vessel_id, time))), vessel(vessel_id), at(time) {}
  std::int64_t vessel;
  double at;

  // what(), with the settings to change named through placeholders (core/setting_error.hpp),
  // for a tool to word.
  std::string message() const { return with_placeholders(vessel, at); }

 private:
  static std::string with_placeholders(std::int64_t vessel_id, double time) {
    std::ostringstream m;
    m << "the solution broke down in vessel " << vessel_id << " at t = " << time
      << " s (area not positive or not finite); try a smaller time step (" << placeholder("dt") << " or "
      << placeholder("cfl") << ") or a lower degree (" << placeholder("degree") << ")";
    return m.str();
  }
};

}  // namespace hemotree
