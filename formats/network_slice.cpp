#include "formats/network_slice.hpp"

#include <algorithm>
#include <cstdio>
#include <memory>
#include <stdexcept>

#include "formats/hdf5_file.hpp"
#include "formats/network_io.hpp"

namespace hemotree {

std::int32_t NetworkSlice::node_at(std::int32_t row) const {
  const auto it = std::lower_bound(node_row.begin(), node_row.end(), row);
  return it != node_row.end() && *it == row ? static_cast<std::int32_t>(it - node_row.begin()) : -1;
}

bool is_hdf5_network_file(const std::string& path) {
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"), &std::fclose);
  char first[8] = {};
  return file && std::fread(first, 1, sizeof first, file.get()) == sizeof first && hdf5::has_signature(first);
}

Network read_network_topology(const std::string& path) { return read_network_topology_hdf5(hdf5::File::open(path)); }

NetworkSlice read_network_slice(const std::string& path, const Network& topology, std::span<const std::int32_t> vessels) {
  return read_network_slice_hdf5(hdf5::File::open(path), topology, vessels);
}

Network topology_of(const Network& whole) {
  Network t;
  t.node_id = whole.node_id;
  t.id = whole.id;
  t.from = whole.from;
  t.to = whole.to;
  t.blood = whole.blood;
  t.inlet = whole.inlet;
  t.boundaries = whole.boundaries;
  t.provenance = whole.provenance;
  t.extra = whole.extra;
  return t;
}

NetworkSlice slice_of(const Network& whole, std::span<const std::int32_t> vessels) {
  NetworkSlice out;
  out.vessel_row.assign(vessels.begin(), vessels.end());
  for (std::size_t k = 0; k < vessels.size(); ++k)
    if (vessels[k] < 0 || static_cast<std::size_t>(vessels[k]) >= whole.vessel_count() ||
        (k > 0 && vessels[k] <= vessels[k - 1]))
      throw std::invalid_argument("slice_of: the rows must increase within the vessels");
  for (const std::int32_t v : vessels) {
    out.node_row.push_back(whole.from[static_cast<std::size_t>(v)]);
    out.node_row.push_back(whole.to[static_cast<std::size_t>(v)]);
  }
  std::sort(out.node_row.begin(), out.node_row.end());
  out.node_row.erase(std::unique(out.node_row.begin(), out.node_row.end()), out.node_row.end());
  Network& net = out.net;
  auto pick = [](const auto& column, const std::vector<std::int32_t>& rows) {
    std::remove_cvref_t<decltype(column)> part;
    if (column.empty()) return part;
    part.reserve(rows.size());
    for (const std::int32_t r : rows) part.push_back(column[static_cast<std::size_t>(r)]);
    return part;
  };
  const std::vector<std::int32_t>& vs = out.vessel_row;
  net.node_id = pick(whole.node_id, out.node_row);
  net.x = pick(whole.x, out.node_row);
  net.y = pick(whole.y, out.node_row);
  net.z = pick(whole.z, out.node_row);
  net.id = pick(whole.id, vs);
  for (const std::int32_t v : vs) {
    net.from.push_back(out.node_at(whole.from[static_cast<std::size_t>(v)]));
    net.to.push_back(out.node_at(whole.to[static_cast<std::size_t>(v)]));
  }
  net.length = pick(whole.length, vs);
  net.diameter = pick(whole.diameter, vs);
  net.wall_thickness = pick(whole.wall_thickness, vs);
  net.youngs_modulus = pick(whole.youngs_modulus, vs);
  net.generation = pick(whole.generation, vs);
  net.vessel_class = pick(whole.vessel_class, vs);
  net.beta = pick(whole.beta, vs);
  net.reference_pressure = pick(whole.reference_pressure, vs);
  net.distal_diameter = pick(whole.distal_diameter, vs);
  net.blood = whole.blood;
  if (whole.inlet && std::binary_search(vs.begin(), vs.end(), static_cast<std::int32_t>(whole.index_of(whole.inlet->vessel))))
    net.inlet = whole.inlet;
  for (const Outlet& o : whole.outlets) {
    const auto it = std::lower_bound(vs.begin(), vs.end(), o.vessel);
    if (it == vs.end() || *it != o.vessel) continue;
    net.outlets.push_back(o);
    net.outlets.back().vessel = static_cast<std::int32_t>(it - vs.begin());
  }
  for (const NodeBoundary& b : whole.boundaries)
    if (const std::int32_t node = out.node_at(b.node); node >= 0) {
      net.boundaries.push_back(b);
      net.boundaries.back().node = node;
    }
  net.provenance = whole.provenance;
  net.extra = whole.extra;
  return out;
}

}  // namespace hemotree
