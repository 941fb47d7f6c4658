// Networks as generic graphs: GraphML (networkx.write_graphml, hemotree's own export) and
// networkx's node-link JSON (networkx.node_link_data, "links" or "edges"). Vessel properties
// are edge attributes (length, diameter or radius, ...). Mapping: docs/import.md.
#pragma once

#include <string>

#include "exchange/foreign_format.hpp"

namespace hemotree {

Network read_graphml(const std::string& path, const ImportOptions& options);
Network read_node_link_json(const std::string& path, const ImportOptions& options);

}  // namespace hemotree
