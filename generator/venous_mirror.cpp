#include "generator/venous_mirror.hpp"

#include <algorithm>
#include <limits>

#include "formats/topology.hpp"

namespace hemotree {

void add_venous_mirror(Network& net, const VenousMirror& mirror) {
  const std::size_t root = check_rooted_tree(net);
  const std::size_t arteries = net.vessel_count(), nodes = net.node_count();
  std::vector<unsigned char> continues(nodes, 0);  // a vessel leaves the node
  for (std::size_t v = 0; v < arteries; ++v) continues[static_cast<std::size_t>(net.from[v])] = 1;

  // Every node but the capillaries' ends gets a venous twin.
  std::vector<std::int32_t> twin(nodes, -1);
  std::int64_t next_id = 0;
  for (std::int64_t id : net.node_id) next_id = std::max(next_id, id + 1);
  net.reserve(2 * arteries, 2 * nodes);
  for (std::size_t i = 0; i < nodes; ++i) {
    if (!continues[i]) {
      twin[i] = static_cast<std::int32_t>(i);  // shared: the capillary joins the two trees here
      continue;
    }
    twin[i] = net.has_coordinates() ? net.add_node(next_id++, net.x[i], net.y[i], net.z[i] - mirror.offset)
                                    : net.add_node(next_id++);
  }
  std::int64_t vessel_id = 0;
  for (std::int64_t id : net.id) vessel_id = std::max(vessel_id, id + 1);
  for (std::size_t k = arteries; k-- > 0;) {
    net.add_vessel(vessel_id++, twin[static_cast<std::size_t>(net.to[k])], twin[static_cast<std::size_t>(net.from[k])],
                   net.length[k], mirror.diameter_ratio * net.diameter[k],
                   mirror.diameter_ratio * net.wall_thickness[k], net.youngs_modulus[k], 0);
  }
  if (!net.distal_diameter.empty()) net.distal_diameter.resize(net.vessel_count(), std::numeric_limits<double>::quiet_NaN());
  if (!net.beta.empty()) {
    net.beta.resize(net.vessel_count(), std::numeric_limits<double>::quiet_NaN());
    net.reference_pressure.resize(net.vessel_count(), std::numeric_limits<double>::quiet_NaN());
  }
  net.generation = generations_from_inlets(net);

  NodeBoundary inflow, outflow;
  inflow.node = net.from[root];
  inflow.type = BoundaryType::flow;
  inflow.waveform = Waveform::constant_value(mirror.mean_flow);
  outflow.node = twin[static_cast<std::size_t>(net.from[root])];
  outflow.type = BoundaryType::pressure;
  outflow.waveform = Waveform::constant_value(mirror.venous_pressure);
  net.boundaries = {inflow, outflow};
  std::sort(net.boundaries.begin(), net.boundaries.end(),
            [](const NodeBoundary& a, const NodeBoundary& b) { return a.node < b.node; });
}

}  // namespace hemotree
