// VTK XML PolyData for ParaView: the nodes are the points and each vessel is a two-point
// line cell carrying its properties as cell data. ASCII arrays, written number by number
// straight into the output stream, so a tree of millions of vessels never sits in memory
// as text.
#include <cmath>
#include <string>

#include "cli/errors.hpp"
#include "formats/exports.hpp"

namespace hemotree {

// Field names and file names come from callers; keep them from breaking the XML.
std::string xml_attribute(std::string_view text) {
  std::string escaped;
  for (char c : text) {
    switch (c) {
      case '&': escaped += "&amp;"; break;
      case '<': escaped += "&lt;"; break;
      case '>': escaped += "&gt;"; break;
      case '"': escaped += "&quot;"; break;
      default: escaped += c;
    }
  }
  return escaped;
}

namespace {

// Writes one ASCII DataArray of `count` tuples; write_tuple(i) streams the numbers of tuple
// i separated by spaces. Scalars go several to a line, vectors one to a line, which keeps
// the file readable without long lines.
template <class WriteTuple>
void write_data_array(OutputStream& out, std::string_view type, std::string_view name,
                      int components, std::size_t count, WriteTuple write_tuple) {
  out << "        <DataArray type=\"" << type << "\" Name=\"" << xml_attribute(name) << '"';
  if (components > 1) out << " NumberOfComponents=\"" << components << '"';
  out << " format=\"ascii\">\n";
  const std::size_t tuples_per_line = components > 1 ? 1 : 8;
  for (std::size_t i = 0; i < count; ++i) {
    write_tuple(i);
    out << ((i + 1) % tuples_per_line == 0 || i + 1 == count ? '\n' : ' ');
  }
  out << "        </DataArray>\n";
}

template <class Number>
void write_cell_array(OutputStream& out, std::string_view type, std::string_view name,
                      std::span<const Number> values) {
  write_data_array(out, type, name, 1, values.size(), [&](std::size_t v) { out << values[v]; });
}

}  // namespace

void write_vtk(const Network& net, OutputStream& out, const std::vector<CellField>& extra) {
  if (!net.has_coordinates())
    throw InputError("VTK export needs node coordinates; this network has none");
  const std::size_t vessels = net.vessel_count();
  const std::size_t nodes = net.node_count();
  // Check before writing anything: a short field found halfway would leave half a file.
  for (const CellField& field : extra)
    if (field.values.size() != vessels)
      throw InputError("cell field '" + field.name + "' has " +
                       std::to_string(field.values.size()) + " values for " +
                       std::to_string(vessels) + " vessels");

  out << "<?xml version=\"1.0\"?>\n"
         "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" "
         "header_type=\"UInt64\">\n"
         "  <PolyData>\n";
  out << "    <Piece NumberOfPoints=\"" << nodes << "\" NumberOfVerts=\"0\" NumberOfLines=\""
      << vessels << "\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n";

  out << "      <Points>\n";
  write_data_array(out, "Float64", "Points", 3, nodes,
                   [&](std::size_t n) { out << net.x[n] << ' ' << net.y[n] << ' ' << net.z[n]; });
  out << "      </Points>\n";

  // Line cells: every vessel joins its two nodes, so the offsets are 2, 4, 6, ...
  out << "      <Lines>\n";
  write_data_array(out, "Int64", "connectivity", 1, vessels,
                   [&](std::size_t v) { out << net.from[v] << ' ' << net.to[v]; });
  write_data_array(out, "Int64", "offsets", 1, vessels,
                   [&](std::size_t v) { out << static_cast<long long>(2 * (v + 1)); });
  out << "      </Lines>\n";

  out << "      <CellData Scalars=\"diameter\">\n";
  write_cell_array<std::int64_t>(out, "Int64", "id", net.id);
  write_cell_array<double>(out, "Float64", "diameter", net.diameter);
  write_cell_array<double>(out, "Float64", "length", net.length);
  write_cell_array<double>(out, "Float64", "wall_thickness", net.wall_thickness);
  write_cell_array<double>(out, "Float64", "youngs_modulus", net.youngs_modulus);
  write_cell_array<std::int32_t>(out, "Int32", "generation", net.generation);
  write_data_array(out, "UInt8", "class", 1, vessels,
                   [&](std::size_t v) { out << static_cast<int>(net.vessel_class[v]); });
  // Results may be undefined in some vessels (a wave speed with no forward wave): VTK's
  // ASCII reader takes "nan" (ParaView shows it in the NaN colour), unlike JSON.
  for (const CellField& field : extra)
    write_data_array(out, "Float64", field.name, 1, field.values.size(), [&](std::size_t v) {
      if (std::isfinite(field.values[v])) out << field.values[v];
      else out << "nan";
    });
  out << "      </CellData>\n"
         "    </Piece>\n"
         "  </PolyData>\n"
         "</VTKFile>\n";
}

}  // namespace hemotree
