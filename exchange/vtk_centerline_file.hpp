// What a VTK centerline file holds, whatever its format, and the readers of its two formats
// (exchange/vtk_*.cpp; private to exchange/): the XML PolyData reader (vtk_xml.cpp), the legacy
// ASCII one (vtk_legacy.cpp), and the network built from their geometry (vtk_centerline.cpp).
#pragma once

#include <charconv>
#include <cstdint>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "exchange/vtk_centerline.hpp"

namespace hemotree::vtk {

// What the file holds, in the file's units: points, one radius per point, polylines as
// point ids (cell c is connectivity[offsets[c] .. offsets[c + 1])).
struct Centerlines {
  std::vector<double> xyz;  // 3 per point
  std::vector<double> radius;
  std::vector<std::int64_t> offsets{0};
  std::vector<std::int64_t> connectivity;
  std::vector<std::string> point_arrays, cell_arrays;  // every array's name, for notes
  std::vector<double> group_ids;                        // cell data GroupIds, if any
  std::size_t vertices = 0;                             // vertex cells, not imported
  std::size_t point_count() const { return radius.size(); }
  std::size_t cell_count() const { return offsets.size() - 1; }
};

inline std::string join(const std::vector<std::string>& names) {
  if (names.empty()) return "none";
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

inline bool parse_double(std::string_view text, double& value) {
  const auto r = std::from_chars(text.data(), text.data() + text.size(), value);
  return r.ec == std::errc() && r.ptr == text.data() + text.size();
}

inline bool is_space(char c) { return c == ' ' || c == '\n' || c == '\r' || c == '\t'; }

// The centerlines of a VTK XML PolyData file (.vtp), its text in `text`.
Centerlines read_xml(const std::string& path, std::string text, const CenterlineOptions& options);

// The centerlines of a legacy ASCII VTK file, its text (from "# vtk DataFile") in `text`.
Centerlines read_legacy(const std::string& path, std::string text, const CenterlineOptions& options);

}  // namespace hemotree::vtk
