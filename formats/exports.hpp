// Exports of a network for other tools: ParaView (VTK XML PolyData), graph tools
// (GraphML and Graphviz dot through Boost.Graph's writers) and spreadsheets (CSV).
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "formats/network.hpp"
#include "formats/output_stream.hpp"

namespace hemotree {

enum class ExportFormat { json, h5, vtk, graphml, dot, csv };
std::optional<ExportFormat> parse_export_format(std::string_view name);
std::string_view to_string(ExportFormat format);
// The format a tool writes: the one named (--format), else h5 for an output file named
// *.h5, else json. Throws InputError for an unknown name.
ExportFormat output_format(const std::string& named, const std::string& output_path);

// A per-vessel quantity to attach as VTK cell data (e.g. simulation results).
struct CellField {
  std::string name;
  std::span<const double> values;  // one per vessel
};

// Points are the node coordinates (InputError if the network has none), one line cell per
// vessel; cell data: id, diameter, length, wall_thickness, youngs_modulus, generation,
// class (0 artery, 1 small_artery, 2 arteriole, 3 capillary), then the extra fields.
// keep: one entry per vessel, 1 = written (empty: every vessel); only the nodes the written
// vessels use become points.
void write_vtk(const Network& net, OutputStream& out, const std::vector<CellField>& extra = {},
               std::span<const std::uint8_t> keep = {});

// Text escaped for an XML attribute value (& < > ").
std::string xml_attribute(std::string_view text);
void write_graphml(const Network& net, OutputStream& out);
void write_dot(const Network& net, OutputStream& out);
void write_csv(const Network& net, OutputStream& out);

// Dispatches on format; json and h5 are the native format's two forms (write_network,
// write_network_hdf5).
void write_network_as(const Network& net, ExportFormat format, OutputStream& out);

}  // namespace hemotree
