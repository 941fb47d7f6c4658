#include "cli/units.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <string>
#include <utility>

#include "cli/errors.hpp"

namespace hemotree {

namespace {

// value_in_si = value * multiply / divide: dividing by 1e6 for micrometres keeps "10um"
// exactly 10e-6 (multiplying by 1e-6 gives 9.999999999999999e-06, a capillary).
struct Unit {
  std::string_view symbol;
  Dimension dimension;
  double multiply = 1.0, divide = 1.0;
};

// The units people use for each quantity; "um" stands for micrometres as well as "µm".
constexpr std::array units{
    Unit{"m", Dimension::length},
    Unit{"cm", Dimension::length, 1, 1e2},
    Unit{"mm", Dimension::length, 1, 1e3},
    Unit{"um", Dimension::length, 1, 1e6},
    Unit{"\xC2\xB5m", Dimension::length, 1, 1e6},
    Unit{"nm", Dimension::length, 1, 1e9},
    Unit{"Pa", Dimension::pressure},
    Unit{"kPa", Dimension::pressure, 1e3},
    Unit{"mmHg", Dimension::pressure, pascal_per_mmhg},
    Unit{"m3/s", Dimension::flow},
    Unit{"m^3/s", Dimension::flow},
    Unit{"ml/s", Dimension::flow, 1, 1e6},
    Unit{"ml/min", Dimension::flow, 1, 60e6},
    Unit{"ul/min", Dimension::flow, 1, 60e9},
    Unit{"nl/min", Dimension::flow, 1, 60e12},
    Unit{"s", Dimension::time},
    Unit{"ms", Dimension::time, 1, 1e3},
    Unit{"us", Dimension::time, 1, 1e6},
    Unit{"Pa s", Dimension::viscosity},
    Unit{"Pas", Dimension::viscosity},
    Unit{"mPa s", Dimension::viscosity, 1, 1e3},
    Unit{"mPas", Dimension::viscosity, 1, 1e3},
    Unit{"cP", Dimension::viscosity, 1, 1e3},
};

std::string_view si_name(Dimension d) {
  switch (d) {
    case Dimension::length: return "m, cm, mm, um, nm";
    case Dimension::pressure: return "Pa, kPa, mmHg";
    case Dimension::flow: return "m3/s, ml/s, ml/min, ul/min, nl/min";
    case Dimension::time: return "s, ms, us";
    case Dimension::viscosity: return "Pa s, mPa s, cP";
    case Dimension::dimensionless: return "none";
  }
  return "";
}

}  // namespace

double parse_quantity(std::string_view text, Dimension dim, std::string_view what) {
  auto bad = [&](const std::string& why) {
    return InputError(std::string(what) + ": '" + std::string(text) + "' " + why);
  };
  std::size_t start = text.find_first_not_of(' ');
  if (start == std::string_view::npos) throw bad("is empty");
  text.remove_prefix(start);
  double value = 0;
  auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || !std::isfinite(value)) throw bad("is not a number");
  std::string_view unit = text.substr(static_cast<std::size_t>(end - text.data()));
  while (!unit.empty() && unit.front() == ' ') unit.remove_prefix(1);
  if (unit.empty()) return value;  // plain SI
  for (const Unit& u : units)
    if (u.symbol == unit && u.dimension == dim) return value * u.multiply / u.divide;
  throw bad("has an unknown unit '" + std::string(unit) + "' (use " +
            std::string(si_name(dim)) + ", or a plain SI number)");
}

}  // namespace hemotree
