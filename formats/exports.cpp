#include "formats/exports.hpp"

#include "core/errors.hpp"
#include "formats/network_io.hpp"

namespace hemotree {

namespace {
constexpr ExportFormat all_formats[] = {ExportFormat::json, ExportFormat::h5, ExportFormat::vtk,
                                        ExportFormat::graphml, ExportFormat::dot,
                                        ExportFormat::csv};
}  // namespace

std::string_view to_string(ExportFormat format) {
  switch (format) {
    case ExportFormat::json: return "json";
    case ExportFormat::h5: return "h5";
    case ExportFormat::vtk: return "vtk";
    case ExportFormat::graphml: return "graphml";
    case ExportFormat::dot: return "dot";
    case ExportFormat::csv: return "csv";
  }
  return "unknown";
}

std::optional<ExportFormat> parse_export_format(std::string_view name) {
  for (ExportFormat format : all_formats)
    if (to_string(format) == name) return format;
  return std::nullopt;
}

ExportFormat output_format(const std::string& named, const std::string& output_path) {
  if (!named.empty()) {
    if (const auto format = parse_export_format(named)) return *format;
    throw InputError("--format: unknown format '" + named + "'");
  }
  const bool h5 = output_path.size() > 3 && output_path.compare(output_path.size() - 3, 3, ".h5") == 0;
  return h5 ? ExportFormat::h5 : ExportFormat::json;
}

void write_network_as(const Network& net, ExportFormat format, OutputStream& out) {
  switch (format) {
    case ExportFormat::json: write_network(net, out); return;
    case ExportFormat::h5: write_network_hdf5(net, out); return;
    case ExportFormat::vtk: write_vtk(net, out); return;
    case ExportFormat::graphml: write_graphml(net, out); return;
    case ExportFormat::dot: write_dot(net, out); return;
    case ExportFormat::csv: write_csv(net, out); return;
  }
}

}  // namespace hemotree
