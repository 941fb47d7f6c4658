#include "solver/network_boundaries.hpp"

#include <algorithm>

#include "cli/errors.hpp"

namespace hemotree {

NetworkBoundaries build_boundaries(const Network& net, const std::vector<std::int32_t>& first_element,
                                   int elements_per_vessel, const std::vector<bool>& zero_d) {
  auto name = [&](std::size_t v) { return "vessel " + std::to_string(net.id[v]); };
  const std::size_t n = net.vessel_count();
  if (n == 0) throw InputError("the network has no vessels");
  if (!net.inlet) throw InputError("the network has no inlet (vprune adds one; see docs/network-format.md)");
  const std::int64_t inlet = net.index_of(net.inlet->vessel);
  if (inlet < 0) throw InputError("inlet: unknown vessel " + std::to_string(net.inlet->vessel));

  // Ends meeting at each node.
  std::vector<std::vector<VesselEnd>> at_node(net.node_count());
  for (std::size_t v = 0; v < n; ++v) {
    at_node[net.from[v]].push_back({static_cast<std::int32_t>(v), first_element[v], false});
    at_node[net.to[v]].push_back({static_cast<std::int32_t>(v), first_element[v] + elements_per_vessel - 1, true});
  }
  std::vector<std::int32_t> outlet_of(n, -1);
  for (std::size_t k = 0; k < net.outlets.size(); ++k) outlet_of[net.outlets[k].vessel] = static_cast<std::int32_t>(k);

  NetworkBoundaries b;
  b.end_state.resize(2 * n);
  b.inlet.vessel = -1;
  b.inflow = net.inlet->waveform;
  for (std::size_t node = 0; node < at_node.size(); ++node) {
    const auto& ends = at_node[node];
    if (ends.empty()) continue;
    const auto v0 = static_cast<std::size_t>(ends[0].vessel);
    const bool lumped = std::any_of(ends.begin(), ends.end(), [&](const VesselEnd& e) { return zero_d[e.vessel]; });
    if (ends.size() == 1) {
      if (lumped) {  // the 0D vessel's inlet or outlet: solver/lumped_vessels
        if (!ends[0].distal && static_cast<std::int64_t>(v0) != inlet)
          throw InputError(name(v0) + " starts at node " + std::to_string(net.node_id[node]) +
                           ", which no vessel feeds and which is not the inlet");
        if (ends[0].distal && outlet_of[v0] < 0) throw InputError(name(v0) + " is terminal but has no outlet");
        continue;
      }
      const VesselEnd e = ends[0];
      if (!e.distal) {
        if (static_cast<std::int64_t>(v0) != inlet)
          throw InputError(name(v0) + " starts at node " + std::to_string(net.node_id[node]) +
                           ", which no vessel feeds and which is not the inlet");
        b.inlet = e;
      } else {
        if (outlet_of[v0] < 0)
          throw InputError(name(v0) + " is terminal but has no outlet");
        NetworkBoundaries::OutletEnd o;
        o.end = e;
        o.index = outlet_of[v0];
        o.outlet = net.outlets[static_cast<std::size_t>(o.index)];
        if (o.outlet.type == OutletType::rcr && o.outlet.c > 0)
          o.capacitor = static_cast<std::int32_t>(b.capacitors++);
        b.outlets.push_back(o);
      }
      continue;
    }
    for (const VesselEnd& e : ends) {
      if (!e.distal && static_cast<std::int64_t>(e.vessel) == inlet)
        throw InputError("inlet: " + name(static_cast<std::size_t>(inlet)) +
                         " does not start at a free node (other vessels meet there)");
      if (e.distal && outlet_of[e.vessel] >= 0)
        throw InputError(name(static_cast<std::size_t>(e.vessel)) +
                         " has an outlet but other vessels continue from its end");
    }
    if (lumped) {
      for (const VesselEnd& e : ends)
        if (!zero_d[e.vessel]) b.coupled.push_back({e, static_cast<std::int64_t>(node)});
      continue;
    }
    if (ends.size() > 16)
      throw InputError("node " + std::to_string(net.node_id[node]) + " joins more than 16 vessels");
    b.junction_ends.insert(b.junction_ends.end(), ends.begin(), ends.end());
    b.junction_offset.push_back(static_cast<std::int64_t>(b.junction_ends.size()));
    b.junction_node.push_back(net.node_id[node]);
  }
  if (b.inflow.period <= 0) throw InputError("inlet: the waveform needs a positive period");
  return b;
}

}  // namespace hemotree
