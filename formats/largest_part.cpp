#include "formats/largest_part.hpp"

#include <algorithm>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "core/errors.hpp"
#include "formats/connected_parts.hpp"
#include "formats/topology.hpp"

namespace hemotree {

namespace {

// The entries of a per-vessel or per-node array at the kept positions; an optional array
// (empty: no vessel has the field) stays empty.
template <typename T>
void keep_only(std::vector<T>& values, const std::vector<std::int32_t>& kept) {
  if (values.empty()) return;
  std::vector<T> out;
  out.reserve(kept.size());
  for (const std::int32_t k : kept) out.push_back(values[static_cast<std::size_t>(k)]);
  values = std::move(out);
}

}  // namespace

Network largest_connected_part(const Network& net, DroppedParts* dropped) {
  if (net.vessel_count() == 0) throw InputError("the network has no vessels, so no connected part to keep");
  const ConnectedParts parts = connected_parts(net);
  const std::int32_t largest = 0;  // parts come largest first

  // Kept positions in their old order, and each old node's new index (-1: dropped).
  std::vector<std::int32_t> kept_vessels, kept_nodes, new_node(net.node_count(), -1), new_vessel(net.vessel_count(), -1);
  for (std::size_t i = 0; i < net.node_count(); ++i)
    if (parts.part_of_node[i] == largest) {
      new_node[i] = static_cast<std::int32_t>(kept_nodes.size());
      kept_nodes.push_back(static_cast<std::int32_t>(i));
    }
  for (std::size_t v = 0; v < net.vessel_count(); ++v)
    if (parts.part_of_node[static_cast<std::size_t>(net.from[v])] == largest) {
      new_vessel[v] = static_cast<std::int32_t>(kept_vessels.size());
      kept_vessels.push_back(static_cast<std::int32_t>(v));
    }

  Network part = net;  // blood, provenance, extra members and whatever else is not per vessel or node
  for (auto* nodes : {&part.x, &part.y, &part.z}) keep_only(*nodes, kept_nodes);
  keep_only(part.node_id, kept_nodes);
  keep_only(part.id, kept_vessels);
  keep_only(part.from, kept_vessels);
  keep_only(part.to, kept_vessels);
  for (std::int32_t& i : part.from) i = new_node[static_cast<std::size_t>(i)];
  for (std::int32_t& i : part.to) i = new_node[static_cast<std::size_t>(i)];
  for (auto* field : {&part.length, &part.diameter, &part.wall_thickness, &part.youngs_modulus, &part.beta,
                      &part.reference_pressure, &part.distal_diameter})
    keep_only(*field, kept_vessels);
  keep_only(part.generation, kept_vessels);
  keep_only(part.vessel_class, kept_vessels);

  // Conditions on kept nodes and vessels; their order (by node, by vessel) survives.
  if (net.inlet) {
    const std::int64_t v = net.index_of(net.inlet->vessel);
    if (v < 0 || new_vessel[static_cast<std::size_t>(v)] < 0) part.inlet.reset();
  }
  part.outlets.clear();
  for (Outlet o : net.outlets)
    if (o.vessel >= 0 && static_cast<std::size_t>(o.vessel) < net.vessel_count() &&
        new_vessel[static_cast<std::size_t>(o.vessel)] >= 0) {
      o.vessel = new_vessel[static_cast<std::size_t>(o.vessel)];
      part.outlets.push_back(o);
    }
  part.boundaries.clear();
  for (NodeBoundary b : net.boundaries)
    if (new_node[static_cast<std::size_t>(b.node)] >= 0) {
      b.node = new_node[static_cast<std::size_t>(b.node)];
      part.boundaries.push_back(b);
    }

  // The format bounds generations by the vessel count: a kept part's own counting stays
  // within its size, but a count over the whole network need not.
  const bool recount = std::any_of(part.generation.begin(), part.generation.end(), [&](std::int32_t g) {
    return static_cast<std::size_t>(g) >= part.vessel_count();
  });
  if (recount) part.generation = generations_from_inlets(part);

  if (dropped) {
    dropped->parts = parts.parts.size() - 1;
    dropped->vessels = net.vessel_count() - part.vessel_count();
    dropped->nodes = net.node_count() - part.node_count();
    dropped->boundary_nodes = node_boundaries(net).size() - parts.parts.front().boundary_nodes.size();
    dropped->generations_recounted = recount;
  }
  return part;
}

std::string describe(const Network& kept, const DroppedParts& dropped) {
  const auto count = [](std::size_t k, const std::string& one, const std::string& many) {
    return std::to_string(k) + " " + (k == 1 ? one : many);
  };
  std::string s = "kept the largest connected part, " + count(kept.vessel_count(), "vessel", "vessels") + " and " +
                  count(kept.node_count(), "node", "nodes");
  if (dropped.parts > 0)
    s += "; dropped " + count(dropped.parts, "part", "parts") + ": " + count(dropped.vessels, "vessel", "vessels") +
         ", " + count(dropped.nodes, "node", "nodes") + ", " +
         count(dropped.boundary_nodes, "boundary node", "boundary nodes");
  else if (dropped.nodes > 0)
    s += "; the network is one part: dropped only " + count(dropped.nodes, "node", "nodes") + " that no vessel meets";
  else
    s += "; the network is one part: nothing dropped";
  if (dropped.generations_recounted)
    s += "; the kept vessels' generations exceeded their count and were counted again from the part's inlets";
  return s;
}

}  // namespace hemotree
