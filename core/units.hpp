// Quantities as people write them: plain SI numbers, or a number with the unit people use
// ("1mm", "7um", "10mmHg", "1.74ml/min"). Everything is converted to SI on entry, and every
// value is checked against the range its setting accepts before any work is done. In the
// core: the tools parse their flags with it, the libraries print quantities with it.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace hemotree {

enum class Dimension { length, pressure, flow, time, viscosity, dimensionless };

// Throws InputError("<what>: ...") when the text is not a number with a unit of dim.
double parse_quantity(std::string_view text, Dimension dim, std::string_view what);

// The values a setting accepts, in SI; an open end excludes its bound.
struct Interval {
  double min, max;
  bool min_open = false, max_open = false;
  bool contains(double value) const;
};

// "[0.01, 100] s", "(1, 2]": the bounds converted to unit (a symbol parse_quantity knows,
// or "" for a dimensionless number), with six significant digits.
std::string describe(const Interval& range, std::string_view unit);

// parse_quantity, then InputError("<what>: '<text>' lies outside the accepted range ...")
// when the value is not in range; the range is stated in unit.
double parse_quantity(std::string_view text, Dimension dim, std::string_view what,
                      const Interval& range, std::string_view unit);

// A plain number (a setting without a unit, such as alpha) within range.
double parse_number(std::string_view text, std::string_view what, const Interval& range);

// A decimal integer in [min, max]: no sign, no exponent, no silent wrap of "-1" or
// saturation of an integer too large for 64 bits.
std::uint64_t parse_count(std::string_view text, std::string_view what, std::uint64_t min,
                          std::uint64_t max);

// The same for a signed integer in [min, max] (a vessel id).
std::int64_t parse_integer(std::string_view text, std::string_view what, std::int64_t min,
                           std::int64_t max);

// A number for a message: six significant digits ("81142.2", "1e+300"), never cut short.
std::string format_rounded(double value);
// An SI value in unit, with the unit: format_quantity(1333.22, "mmHg") is "10 mmHg".
std::string format_quantity(double value_si, std::string_view unit);

// Conversions for printing.
inline constexpr double pascal_per_mmhg = 133.322;
inline constexpr double m3s_per_ml_min = 1e-6 / 60.0;

}  // namespace hemotree
