// vimport graphml and vimport networkx on hostile bytes (one source, built twice: GRAPH_FORMAT
// is "graphml" or "networkx"): read_graphml or read_node_link_json on the input. An accepted
// network must be written as vnet and read back the same (vimport's output), and hemotree's
// GraphML export of it (vgen --format graphml, write_graphml) must read back with the same
// ids, connections, generations and classes, numbers and coordinates within its 9 digits
// (docs/import.md). A refusal is InputError, nothing else.
#include <cstdint>
#include <string>
#include <string_view>

#include "exchange/graph_formats.hpp"
#include "formats/exports.hpp"
#include "import_support.hpp"

using namespace hemotree;
using namespace hemotree::fuzz;

namespace {

const std::string format = GRAPH_FORMAT;

std::string peer_difference(const Network& a, const Network& b) {
  constexpr double rel = 5e-9;
  if (a.vessel_count() != b.vessel_count()) return "vessel counts differ";
  for (const std::string& d :
       {same("vessel ids", a.id, b.id), same("node ids", a.node_id, b.node_id), same("from", a.from, b.from),
        same("to", a.to, b.to), same("generation", a.generation, b.generation),
        same("class", a.vessel_class, b.vessel_class), reals("x", a.x, b.x, rel), reals("y", a.y, b.y, rel),
        reals("z", a.z, b.z, rel), reals("length", a.length, b.length, rel),
        reals("diameter", a.diameter, b.diameter, rel),
        reals("wall_thickness", a.wall_thickness, b.wall_thickness, rel),
        reals("youngs_modulus", a.youngs_modulus, b.youngs_modulus, rel)})
    if (!d.empty()) return d;
  for (std::size_t v = 0; v < a.vessel_count(); ++v)
    if (!close_enough(a.diameter_at_to(v), b.diameter_at_to(v), rel))
      return "vessel " + std::to_string(a.id[v]) + ": distal diameter differs";
  return "";
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  init_import_harness();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto input = scratch() / (format == "graphml" ? "graph.graphml" : "graph.json");
  write_file(input, std::string_view(reinterpret_cast<const char*>(data), size));
  const auto net = refused_or("read " + format, [&] {
    return format == "graphml" ? read_graphml(input.string(), quiet_options())
                               : read_node_link_json(input.string(), quiet_options());
  });
  if (!net) return 0;
  check_vnet_round_trip(*net, format);

  // hemotree's GraphML export: written whatever the network, read back the same.
  const auto written = scratch() / "exported.graphml";
  must("write_graphml", [&] {
    OutputStream out(written.string());
    write_graphml(*net, out);
    out.commit();
    return true;
  });
  const Network back = must("read_graphml refuses what write_graphml wrote",
                            [&] { return read_graphml(written.string(), quiet_options()); });
  if (const std::string d = peer_difference(*net, back); !d.empty())
    finding("GraphML written by hemotree's export and read back: " + d);
  return 0;
}
