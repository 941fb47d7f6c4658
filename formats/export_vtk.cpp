// VTK XML PolyData for ParaView: the nodes are the points and each vessel is a two-point
// line cell carrying its properties as cell data. ASCII arrays, written number by number
// straight into the output stream, so a tree of millions of vessels never sits in memory
// as text.
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/errors.hpp"
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


}  // namespace

void write_vtk(const Network& net, OutputStream& out, const std::vector<CellField>& extra,
               std::span<const std::uint8_t> keep) {
  if (!net.has_coordinates())
    throw InputError("VTK export needs node coordinates; this network has none");
  // Check before writing anything: a short field found halfway would leave half a file.
  for (const CellField& field : extra)
    if (field.values.size() != net.vessel_count())
      throw InputError("cell field '" + field.name + "' has " +
                       std::to_string(field.values.size()) + " values for " +
                       std::to_string(net.vessel_count()) + " vessels");
  if (!keep.empty() && keep.size() != net.vessel_count())
    throw std::invalid_argument("write_vtk: a keep mask of " + std::to_string(keep.size()) + " for " +
                                std::to_string(net.vessel_count()) + " vessels");
  // The cells written (every vessel, or those kept) and the points they use, renumbered.
  std::vector<std::int64_t> cell, point, point_of(keep.empty() ? 0 : net.node_count(), -1);
  for (std::size_t v = 0; v < net.vessel_count(); ++v)
    if (keep.empty() || keep[v]) cell.push_back(static_cast<std::int64_t>(v));
  if (!keep.empty())
    for (const std::int64_t v : cell)
      for (const std::int32_t n : {net.from[static_cast<std::size_t>(v)], net.to[static_cast<std::size_t>(v)]})
        if (point_of[static_cast<std::size_t>(n)] < 0) {
          point_of[static_cast<std::size_t>(n)] = static_cast<std::int64_t>(point.size());
          point.push_back(n);
        }
  const std::size_t vessels = cell.size();
  const std::size_t nodes = keep.empty() ? net.node_count() : point.size();
  auto node = [&](std::size_t k) { return keep.empty() ? k : static_cast<std::size_t>(point[k]); };
  auto renumbered = [&](std::int32_t n) {
    return keep.empty() ? static_cast<std::int64_t>(n) : point_of[static_cast<std::size_t>(n)];
  };
  auto vessel = [&](std::size_t i) { return static_cast<std::size_t>(cell[i]); };

  out << "<?xml version=\"1.0\"?>\n"
         "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" "
         "header_type=\"UInt64\">\n"
         "  <PolyData>\n";
  out << "    <Piece NumberOfPoints=\"" << nodes << "\" NumberOfVerts=\"0\" NumberOfLines=\""
      << vessels << "\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n";

  out << "      <Points>\n";
  write_data_array(out, "Float64", "Points", 3, nodes,
                   [&](std::size_t k) {
                     const std::size_t n = node(k);
                     out << net.x[n] << ' ' << net.y[n] << ' ' << net.z[n];
                   });
  out << "      </Points>\n";

  // Line cells: every vessel joins its two nodes, so the offsets are 2, 4, 6, ...
  out << "      <Lines>\n";
  write_data_array(out, "Int64", "connectivity", 1, vessels,
                   [&](std::size_t i) {
                     out << static_cast<long long>(renumbered(net.from[vessel(i)])) << ' '
                         << static_cast<long long>(renumbered(net.to[vessel(i)]));
                   });
  write_data_array(out, "Int64", "offsets", 1, vessels,
                   [&](std::size_t v) { out << static_cast<long long>(2 * (v + 1)); });
  out << "      </Lines>\n";

  // Boundary conditions at nodes (measured networks): a code per point, -1 where none.
  const std::vector<NodeBoundary> boundaries = node_boundaries(net);
  if (!boundaries.empty()) {
    std::vector<int> code(net.node_count(), -1);
    for (const NodeBoundary& b : boundaries) code[static_cast<std::size_t>(b.node)] = static_cast<int>(b.type);
    out << "      <PointData>\n";
    write_data_array(out, "Int8", "boundary", 1, nodes, [&](std::size_t k) { out << code[node(k)]; });
    out << "      </PointData>\n";
  }

  out << "      <CellData Scalars=\"diameter\">\n";
  auto cells_of = [&](std::string_view type, std::string_view name, const auto& values) {
    write_data_array(out, type, name, 1, vessels, [&](std::size_t i) { out << values[vessel(i)]; });
  };
  cells_of("Int64", "id", net.id);
  cells_of("Float64", "diameter", net.diameter);
  if (!net.distal_diameter.empty())
    write_data_array(out, "Float64", "distal_diameter", 1, vessels,
                     [&](std::size_t i) { out << net.diameter_at_to(vessel(i)); });
  cells_of("Float64", "length", net.length);
  cells_of("Float64", "wall_thickness", net.wall_thickness);
  cells_of("Float64", "youngs_modulus", net.youngs_modulus);
  cells_of("Int32", "generation", net.generation);
  write_data_array(out, "UInt8", "class", 1, vessels,
                   [&](std::size_t i) { out << static_cast<int>(net.vessel_class[vessel(i)]); });
  // Results may be undefined in some vessels (a wave speed with no forward wave): VTK's
  // ASCII reader takes "nan" (ParaView shows it in the NaN colour), unlike JSON.
  for (const CellField& field : extra)
    write_data_array(out, "Float64", field.name, 1, vessels, [&](std::size_t i) {
      const double x = field.values[vessel(i)];
      if (std::isfinite(x)) out << x;
      else out << "nan";
    });
  out << "      </CellData>\n"
         "    </Piece>\n"
         "  </PolyData>\n"
         "</VTKFile>\n";
}

}  // namespace hemotree
