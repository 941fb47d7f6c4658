// Networks as generic graphs: GraphML (networkx.write_graphml, hemotree's own export) and
// networkx's node-link JSON (networkx.node_link_data, "links" or "edges"). Vessel properties
// are edge attributes (length, diameter or radius, ...), node coordinates node attributes
// x, y, z. Mapping: docs/import.md.
#pragma once

#include <optional>
#include <string>

#include "exchange/foreign_format.hpp"

namespace hemotree {

struct GraphOptions {
  // Metres per unit of the file's lengths (length, diameter, radius, wall_thickness, x, y,
  // z); vimport --unit. Unset: the file's graph attribute "unit" (or "units",
  // "length_unit": m, cm, mm, um, nm), else metres. Both given and different: InputError.
  std::optional<double> length_unit;
};

// Throws InputError "FILE: element: what is wrong" ("FILE:LINE: ..." for a syntax error)
// for a malformed file or a graph that is not a network; IoError when unreadable.
Network read_graphml(const std::string& path, const ImportOptions& options, const GraphOptions& graph = {});
Network read_node_link_json(const std::string& path, const ImportOptions& options, const GraphOptions& graph = {});

}  // namespace hemotree
