// A tool's command line on hostile arguments: the input, split at newlines (and NULs), is
// the argument list of FUZZ_TOOL's main, run in process on the fixtures of tool_runner.hpp.
// Whatever the arguments, the exit status is 0, 1 or 2.
//
// The tool runs for real, not only its parser: most wrong values are caught after parsing,
// in the tool's own checks and the work they guard. So that a run stays a millisecond,
// arguments that only ask for more work of a valid kind are skipped before the run (see
// cheap_enough): vgen trees wider than 3:1 in diameter, hemosolve beyond a few cycles,
// elements, frames, threads or time steps. Hostile values of those flags (negative, NaN,
// infinite, 1e-300, units that do not fit) still run, since they must be refused at once.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/units.hpp"
#include "tool_runner.hpp"

using namespace hemotree;

namespace {

fuzz::ToolRunner* runner = nullptr;

// The value given to flag ("--flag value" or "--flag=value"), if any.
std::optional<std::string> value_of(const std::vector<std::string>& args, std::string_view flag) {
  for (std::size_t i = 0; i < args.size(); ++i) {
    if (args[i] == flag && i + 1 < args.size()) return args[i + 1];
    if (args[i].size() > flag.size() && args[i].compare(0, flag.size(), flag) == 0 && args[i][flag.size()] == '=')
      return args[i].substr(flag.size() + 1);
  }
  return std::nullopt;
}

bool has(const std::vector<std::string>& args, std::string_view flag) {
  for (const auto& a : args)
    if (a == flag) return true;
  return false;
}

// The value as the tool would see it, when it is a valid one; nullopt when the tool must
// refuse it (that run is quick whatever it is).
std::optional<double> quantity(const std::vector<std::string>& args, std::string_view flag, Dimension dim) {
  const auto text = value_of(args, flag);
  if (!text) return std::nullopt;
  try {
    const double v = parse_quantity(*text, dim, flag);
    return std::isfinite(v) ? std::optional<double>(v) : std::nullopt;
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

// A whole number above limit (as strtod reads it: "1e9" counts too).
bool above(const std::vector<std::string>& args, std::string_view flag, double limit) {
  const auto text = value_of(args, flag);
  if (!text) return false;
  char* end = nullptr;
  const double v = std::strtod(text->c_str(), &end);
  return end != text->c_str() && v > limit;
}

// Outputs stay in the scratch folder: no "..", no absolute path ("/x", "--out=/x", "-o/x")
// but the two devices.
bool leaves_scratch(const std::string& a) {
  if (a.find("..") != std::string::npos) return true;
  for (std::size_t p = a.find('/'); p != std::string::npos; p = a.find('/', p + 1)) {
    const bool starts_path = p == 0 || a[p - 1] == '=' || (p == 2 && a.compare(0, 2, "-o") == 0);
    if (!starts_path) continue;
    const std::string_view rest = std::string_view(a).substr(p);
    if (rest != "/dev/null" && rest != "/dev/full") return true;
  }
  return false;
}

bool cheap_enough(std::string_view tool, const std::vector<std::string>& args) {
  if (tool == "vgen") {
    // No shortcut for --help or --print-rules: "-o --help" takes it as the output's name.
    const double root = quantity(args, "--root-diameter", Dimension::length).value_or(
        value_of(args, "--root-diameter") ? -1 : 1e-3);
    const double min = quantity(args, "--min-diameter", Dimension::length).value_or(
        value_of(args, "--min-diameter") ? -1 : 7e-6);
    if (!(root > 0 && min > 0 && min < root)) return true;  // refused before growing
    const double ratio = root / min;
    // Up to 3:1 a tree of a few hundred vessels; beyond 1e9:1 the size estimate refuses it.
    return ratio <= 3 || (ratio > 1e9 && !has(args, "--force"));
  }
  if (tool == "hemosolve") {
    // The fixture's cycle is 10 ms, 45 steps of the default degree. Two threads only change
    // the scheduling, and on a busy machine every barrier of a step can wait a time slice:
    // 1000 steps took 20 s of wall for 1.5 s of CPU under ASan (regressions/cli_hemosolve).
    if (above(args, "--cycles", 3) || above(args, "--max-cycles", 10) || above(args, "--elements", 4) ||
        above(args, "--frames", 4) || above(args, "--threads", 1))
      return false;
    if (value_of(args, "--until-periodic") && !value_of(args, "--max-cycles")) return false;  // 50 cycles
    if (const auto dt = quantity(args, "--dt", Dimension::time); dt && *dt < 1e-5) return false;
    if (const auto cfl = quantity(args, "--cfl", Dimension::dimensionless); cfl && *cfl < 0.1) return false;
    return true;
  }
  return true;  // vstats and vprune on the 13-vessel tree: quick whatever the flags
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  fuzz::keep_report_channel();
  runner = new fuzz::ToolRunner();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::string> args(1);
  for (std::size_t i = 0; i < size; ++i) {
    const char c = static_cast<char>(data[i]);
    if (c == '\n' || c == '\0') {
      if (args.size() == 40) return 0;
      args.emplace_back();
    } else {
      args.back() += c;
    }
  }
  if (size == 0) args.clear();
  for (const auto& a : args)
    if (a.size() > 200 || leaves_scratch(a)) return 0;
  if (!cheap_enough(FUZZ_TOOL, args)) return 0;
  runner->reset();
  runner->run(FUZZ_TOOL, args);
  return 0;
}
