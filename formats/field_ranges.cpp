#include "formats/field_ranges.hpp"

#include <charconv>

namespace hemotree {

std::string format_number(double value) {
  char text[32];
  const auto result = std::to_chars(text, text + sizeof text, value);
  // to_chars writes "1e-07" and "1e+22"; messages read better as "1e-7" and "1e22".
  std::string s;
  const char* c = text;
  while (c < result.ptr && *c != 'e') s += *c++;
  if (c < result.ptr) {
    s += *c++;  // 'e'
    if (*c == '+') ++c;
    else if (*c == '-') s += *c++;
    while (c + 1 < result.ptr && *c == '0') ++c;
    s.append(c, static_cast<std::size_t>(result.ptr - c));
  }
  return s;
}

// Built by appending: GCC 12 warns falsely (-Wrestrict, its bug 105651) on "[" + string.
std::string describe(const FieldRange& range) {
  std::string s(1, '[');
  s += format_number(range.min);
  s += ", ";
  s += format_number(range.max);
  s += ']';
  if (!range.unit.empty()) {
    s += ' ';
    s += range.unit;
  }
  return s;
}

std::string out_of_range(std::string_view field, const FieldRange& range, double got) {
  std::string s(1, '"');
  s += field;
  s += "\" must lie in ";
  s += describe(range);
  s += " (got ";
  s += format_number(got);
  s += ')';
  return s;
}

}  // namespace hemotree
