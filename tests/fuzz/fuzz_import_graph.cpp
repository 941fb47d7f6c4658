// vimport graphml and vimport networkx on hostile bytes (one source, built twice: GRAPH_FORMAT
// is "graphml" or "networkx"): read_graphml or read_node_link_json on the input. An accepted
// network must be written as vnet and read back the same (vimport's output), and hemotree's
// GraphML export of it (vgen --format graphml, write_graphml) must read back with the same
// ids, connections, generations and classes, numbers and coordinates within its 9 digits
// (docs/import.md). A refusal is InputError, nothing else.
#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>

#include "exchange/graph_formats.hpp"
#include "formats/exports.hpp"
#include "import_support.hpp"

using namespace hemotree;
using namespace hemotree::fuzz;

namespace {

const std::string format = GRAPH_FORMAT;

// The export writes the edges grouped by their source node (Boost's compressed sparse row
// graph sorts them), so vessels come back in that order: they are matched by id.
std::string peer_difference(const Network& a, const Network& b) {
  constexpr double rel = 5e-9;
  if (a.vessel_count() != b.vessel_count()) return "vessel counts differ";
  for (const std::string& d : {same("node ids", a.node_id, b.node_id), reals("x", a.x, b.x, rel),
                               reals("y", a.y, b.y, rel), reals("z", a.z, b.z, rel)})
    if (!d.empty()) return d;
  std::map<std::int64_t, std::size_t> index;
  for (std::size_t w = 0; w < b.vessel_count(); ++w) index.emplace(b.id[w], w);
  for (std::size_t v = 0; v < a.vessel_count(); ++v) {
    const std::string which = "vessel " + std::to_string(a.id[v]) + ": ";
    const auto at = index.find(a.id[v]);
    if (at == index.end()) return which + "not read back";
    const std::size_t w = at->second;
    const auto end_id = [](const Network& n, std::int32_t node) { return n.node_id[static_cast<std::size_t>(node)]; };
    if (end_id(a, a.from[v]) != end_id(b, b.from[w]) || end_id(a, a.to[v]) != end_id(b, b.to[w]))
      return which + "other nodes";
    if (a.generation[v] != b.generation[w]) return which + "another generation";
    // The export writes the class of the diameter it writes (9 digits, 6d663c2, finding 7): a
    // diameter within 1e-8 of a class boundary may come back in the class across it.
    bool near_boundary = false;
    for (const double bound : {artery_min_diameter, small_artery_min_diameter, arteriole_min_diameter})
      near_boundary = near_boundary || std::abs(a.diameter[v] - bound) <= 1e-8 * bound;
    if (a.vessel_class[v] != b.vessel_class[w] && !near_boundary) return which + "another class";
    const double pairs[][2] = {{a.length[v], b.length[w]},
                               {a.diameter[v], b.diameter[w]},
                               {a.diameter_at_to(v), b.diameter_at_to(w)},
                               {a.wall_thickness[v], b.wall_thickness[w]},
                               {a.youngs_modulus[v], b.youngs_modulus[w]}};
    const char* names[] = {"length", "diameter", "distal diameter", "wall thickness", "Young's modulus"};
    for (std::size_t k = 0; k < 5; ++k)
      if (!close_enough(pairs[k][0], pairs[k][1], rel))
        return which + names[k] + " " + std::to_string(pairs[k][0]) + " against " + std::to_string(pairs[k][1]);
  }
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
