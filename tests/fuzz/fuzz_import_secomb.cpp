// vimport secomb on hostile bytes: read_secomb on the input as a network.dat; an accepted
// network must be written as vnet and read back the same (vimport's output), and what
// vexport secomb writes of it must read back as the same network (docs/import.md: ids,
// nodes, generations and boundaries equal; diameters, coordinates, lengths and boundary
// values within the printed digits). A refusal is InputError, nothing else.
#include <cstdint>
#include <string>
#include <string_view>

#include "exchange/secomb.hpp"
#include "import_support.hpp"

using namespace hemotree;
using namespace hemotree::fuzz;

namespace {

// network.dat's own reading of a network written by write_secomb against the first reading.
std::string peer_difference(const Network& a, const Network& b) {
  if (a.vessel_count() != b.vessel_count()) return "vessel counts differ";
  if (a.node_count() != b.node_count()) return "node counts differ";
  for (const std::string& d :
       {same("vessel ids", a.id, b.id), same("node ids", a.node_id, b.node_id), same("from", a.from, b.from),
        same("to", a.to, b.to), same("generation", a.generation, b.generation),
        reals("diameter", a.diameter, b.diameter, 5e-9)})
    if (!d.empty()) return d;
  // Coordinates in um with six decimals (1e-12 m); lengths are their distances again.
  for (const std::string& d : {reals("x", a.x, b.x, 5e-9, 1e-12), reals("y", a.y, b.y, 5e-9, 1e-12),
                               reals("z", a.z, b.z, 5e-9, 1e-12), reals("length", a.length, b.length, 5e-9, 4e-12)})
    if (!d.empty()) return d;
  if (a.boundaries.size() != b.boundaries.size()) return "boundary counts differ";
  for (std::size_t k = 0; k < a.boundaries.size(); ++k) {
    const NodeBoundary &p = a.boundaries[k], &q = b.boundaries[k];
    const std::string which = "boundary " + std::to_string(k) + " ";
    if (p.node != q.node) return which + "at another node";
    if (p.type != q.type) return which + "of another type";
    // Values below 1e-300 (subnormal m^3/s: a few bits) only as close as their magnitude.
    if (!close_enough(p.waveform.mean, q.waveform.mean, 5e-9, 1e-300)) return which + "value differs";
    if (std::isnan(p.hematocrit) != std::isnan(q.hematocrit)) return which + "hematocrit present in one only";
    if (!close_enough(p.hematocrit, q.hematocrit, 5e-9)) return which + "hematocrit differs";
  }
  return "";
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  init_import_harness();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto input = scratch() / "network.dat";
  write_file(input, std::string_view(reinterpret_cast<const char*>(data), size));
  const auto net = refused_or("read_secomb", [&] { return read_secomb(input.string(), quiet_options()); });
  if (!net) return 0;
  check_vnet_round_trip(*net, "secomb");

  // vexport secomb: it may refuse what network.dat cannot hold (a boundary where vessels
  // meet, an id beyond 32 bits); what it writes must read back.
  const auto written = scratch() / "exported.dat";
  const auto exported = refused_or("write_secomb", [&] {
    OutputStream out(written.string());
    write_secomb(*net, out);
    out.commit();
    return true;
  });
  if (!exported) return 0;
  const Network back = must("read_secomb refuses what write_secomb wrote",
                            [&] { return read_secomb(written.string(), quiet_options()); });
  if (const std::string d = peer_difference(*net, back); !d.empty())
    finding("network.dat written by vexport secomb and read back: " + d);
  return 0;
}
