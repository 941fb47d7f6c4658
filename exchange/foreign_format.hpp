// What every importer of a foreign network format shares: how to fill what the file lacks
// (wall thickness, Young's modulus) and where to say what was assumed.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "formats/network.hpp"

namespace hemotree {

struct ImportOptions {
  // A Young's modulus [Pa] for every vessel whose file gives none; unset: the toolkit's E(D)
  // table (generator/growth_rules.hpp, default_rules().youngs_modulus).
  std::optional<double> youngs_modulus;
  // A wall thickness as a fraction of the lumen diameter, h = wall_ratio D, for every vessel
  // whose file gives none; unset: the toolkit's per-class wall law (default_rules().wall).
  std::optional<double> wall_ratio;
  // Receives one line per assumption ("vessel wall thickness from h = 0.1 D for 1130
  // vessels"), which names settings through placeholders (core/setting_error.hpp); vimport
  // words them as its flags and prints the lines on stderr.
  std::function<void(const std::string&)> note = [](const std::string&) {};
};

// The whole file as bytes (formats read whole: centerlines, graphs); IoError naming it when it
// cannot be opened or read.
std::string read_whole_file(const std::string& path);

// The deepest element nesting refuse_deep_xml lets through: GraphML and VTK PolyData nest
// fewer than 10 deep, and the recursive XML parser (rapidxml, under Boost.PropertyTree)
// spends a stack frame on each level, so 200,000 nested elements overflow the stack.
constexpr std::size_t xml_depth_cap = 256;

// Refuses, as InputError "PATH:LINE: ...", XML whose elements nest deeper than
// xml_depth_cap, before any recursive parser sees it. One linear pass over the bytes that
// skips comments, CDATA, processing instructions, declarations and quoted attribute values;
// it counts what a parser would, so anything it lets through is at most that deep.
void refuse_deep_xml(const std::string& path, std::string_view xml);

// Fills wall_thickness and youngs_modulus where they are NaN, from the options or the
// toolkit's tables, and notes what it did (one line each, with the count of vessels).
void fill_missing_walls(Network& net, const ImportOptions& options);

// The provenance vimport writes on an imported network: "tool", "version", "format" and
// "source" (and "parameters" where given) over what the reader put there; where a string is
// not UTF-8 (a file name need not be, JSON text must be), its bytes outside ASCII become '?'.
void stamp_import_provenance(Network& net, const std::string& format, const std::string& source,
                             const nlohmann::json& parameters = nlohmann::json::object());

}  // namespace hemotree
