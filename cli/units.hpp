// Quantities on the command line: plain SI numbers, or a number with the unit people use
// ("1mm", "7um", "10mmHg", "1.74ml/min"). Everything is converted to SI on entry.
#pragma once

#include <string>
#include <string_view>

namespace hemotree {

enum class Dimension { length, pressure, flow, time, viscosity, dimensionless };

// Throws InputError("<what>: ...") when the text is not a number with a unit of dim.
double parse_quantity(std::string_view text, Dimension dim, std::string_view what);

// Conversions for printing.
inline constexpr double pascal_per_mmhg = 133.322;
inline constexpr double m3s_per_ml_min = 1e-6 / 60.0;

}  // namespace hemotree
