#include "formats/pressure_reference.hpp"

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "formats/field_ranges.hpp"

namespace hemotree {

namespace {

std::string ml_per_min(double flow) {
  char text[64];
  std::snprintf(text, sizeof text, "%.6g ml/min", flow * 60e6);
  return text;
}

}  // namespace

ConnectedPart fix_pressure_at(Network& net, std::int64_t node_id, double pressure) {
  const std::string refusal = "cannot fix a pressure at node " + std::to_string(node_id) + ": ";
  const auto at = std::find(net.node_id.begin(), net.node_id.end(), node_id);
  if (at == net.node_id.end()) throw InputError(refusal + "the network has no node of that id");
  const auto node = static_cast<std::int32_t>(at - net.node_id.begin());
  if (!ranges::pressure.contains(pressure)) throw InputError(refusal + out_of_range("pressure", ranges::pressure, pressure));

  const std::vector<NodeBoundary> boundaries = node_boundaries(net);
  for (const NodeBoundary& b : boundaries)
    if (b.node == node)
      throw InputError(refusal + "it has a " + std::string(to_string(b.type)) + " boundary already");
  const ConnectedParts parts = connected_parts(net, boundaries);
  const std::int32_t k = parts.part_of_node[static_cast<std::size_t>(node)];
  if (k < 0) throw InputError(refusal + "no vessel meets it");
  const ConnectedPart& part = parts.parts[static_cast<std::size_t>(k)];
  if (part.pressure_reference) {
    std::int64_t reference = -1;
    for (const NodeBoundary& b : boundaries)
      if (b.type != BoundaryType::flow && parts.part_of_node[static_cast<std::size_t>(b.node)] == k) {
        reference = net.node_id[static_cast<std::size_t>(b.node)];
        break;
      }
    throw InputError(refusal + part_name(part) + " has a pressure to refer to already (at node " +
                     std::to_string(reference) + ")");
  }
  if (!part.flows_balance())
    throw InputError(refusal + "the " + (part.time_varying_flows ? "mean flows" : "flows") + " into " +
                     part_name(part) + " do not balance: their sum is " + ml_per_min(part.net_inflow) +
                     " against " + ml_per_min(part.largest_flow) + " at most through one node" +
                     (part.time_varying_flows ? " (waveforms compared by their mean flows)" : "") +
                     ", and a pressure would take up the difference; correct the flows or give an outlet");

  NodeBoundary fixed;
  fixed.node = node;
  fixed.type = BoundaryType::pressure;
  fixed.waveform = Waveform::constant_value(pressure);
  const auto after = std::upper_bound(net.boundaries.begin(), net.boundaries.end(), node,
                                      [](std::int32_t i, const NodeBoundary& b) { return i < b.node; });
  net.boundaries.insert(after, fixed);
  ConnectedPart referred = part;
  referred.boundary_nodes.insert(std::upper_bound(referred.boundary_nodes.begin(), referred.boundary_nodes.end(), node),
                                 node);
  referred.pressure_reference = true;
  return referred;
}

}  // namespace hemotree
