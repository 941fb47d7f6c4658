#include "core/units.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>

#include "core/errors.hpp"

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

// An SI value expressed in unit; unchanged for "" or a unit not in the table.
double in_unit(double value_si, std::string_view unit) {
  for (const Unit& u : units)
    if (u.symbol == unit) return value_si * u.divide / u.multiply;
  return value_si;
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
  // inf, nan and 1e400 are no quantity: refused here, before they reach a computation.
  if (ec != std::errc() || !std::isfinite(value)) throw bad("is not a finite number");
  std::string_view unit = text.substr(static_cast<std::size_t>(end - text.data()));
  while (!unit.empty() && unit.front() == ' ') unit.remove_prefix(1);
  if (unit.empty()) return value;  // plain SI
  if (dim == Dimension::dimensionless) throw bad("is not a finite number");
  for (const Unit& u : units)
    if (u.symbol == unit && u.dimension == dim) {
      const double si = value * u.multiply / u.divide;
      if (!std::isfinite(si)) throw bad("is too large");  // 1e308 mmHg
      return si;
    }
  throw bad("has an unknown unit '" + std::string(unit) + "' (use " +
            std::string(si_name(dim)) + ", or a plain SI number)");
}

bool Interval::contains(double value) const {
  return (min_open ? value > min : value >= min) && (max_open ? value < max : value <= max);
}

std::string describe(const Interval& range, std::string_view unit) {
  std::string text = range.min_open ? "(" : "[";
  text += format_rounded(in_unit(range.min, unit)) + ", " + format_rounded(in_unit(range.max, unit));
  text += range.max_open ? ")" : "]";
  if (!unit.empty()) text += " " + std::string(unit);  // "[0.01, 100] s"
  return text;
}

double parse_quantity(std::string_view text, Dimension dim, std::string_view what,
                      const Interval& range, std::string_view unit) {
  const double value = parse_quantity(text, dim, what);
  if (!range.contains(value))
    throw InputError(std::string(what) + ": '" + std::string(text) +
                     "' lies outside the accepted range " + describe(range, unit));
  return value;
}

double parse_number(std::string_view text, std::string_view what, const Interval& range) {
  return parse_quantity(text, Dimension::dimensionless, what, range, "");
}

namespace {
// A decimal integer of type Int in [min, max]: no exponent, no silent wrap or saturation;
// for an unsigned Int a minus sign is named as such.
template <class Int>
Int parse_whole(std::string_view text, std::string_view what, Int min, Int max) {
  auto bad = [&](const std::string& why) {
    return InputError(std::string(what) + ": '" + std::string(text) + "' " + why +
                      "; the accepted range is " + std::to_string(min) + ".." + std::to_string(max));
  };
  if (text.empty()) throw bad("is empty");
  if (std::is_unsigned_v<Int> && text.front() == '-') throw bad("is negative");
  Int value = 0;
  const char* end = text.data() + text.size();
  auto [stop, ec] = std::from_chars(text.data(), end, value);
  if (ec == std::errc::result_out_of_range) throw bad("is too large");
  if (ec != std::errc() || stop != end) throw bad("is not an integer");
  if (value < min || value > max)
    throw InputError(std::string(what) + ": '" + std::string(text) +
                     "' lies outside the accepted range " + std::to_string(min) + ".." +
                     std::to_string(max));
  return value;
}
}  // namespace

std::uint64_t parse_count(std::string_view text, std::string_view what, std::uint64_t min,
                          std::uint64_t max) {
  return parse_whole(text, what, min, max);
}

std::int64_t parse_integer(std::string_view text, std::string_view what, std::int64_t min,
                           std::int64_t max) {
  return parse_whole(text, what, min, max);
}

std::string format_rounded(double value) {
  char text[32];  // "%.6g" needs at most 13 characters ("-1.23457e+308")
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

std::string format_quantity(double value_si, std::string_view unit) {
  const std::string number = format_rounded(in_unit(value_si, unit));
  return unit.empty() ? number : number + " " + std::string(unit);
}

}  // namespace hemotree
