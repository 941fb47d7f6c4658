#include "pulse/network_boundaries.hpp"

#include <algorithm>
#include <cmath>

#include "core/errors.hpp"
#include "core/setting_error.hpp"

namespace hemotree {

NetworkBoundaries build_boundaries(const Network& net, const std::vector<std::int32_t>& first_element,
                                   int elements_per_vessel, const std::vector<bool>& zero_d) {
  auto name = [&](std::size_t v) { return "vessel " + std::to_string(net.id[v]); };
  auto node_name = [&](std::size_t node) { return "node " + std::to_string(net.node_id[node]); };
  const std::size_t n = net.vessel_count();
  if (n == 0) throw InputError("the network has no vessels");
  if (!net.inlet && net.boundaries.empty())
    throw InputError("the network has no inlet (vprune adds one; see docs/network-format.md)");

  NetworkBoundaries b;
  b.list = RunBoundaries(net);
  std::int32_t elements = 0;
  for (std::size_t v = 0; v < n; ++v)
    if (!zero_d[v]) elements = std::max(elements, first_element[v] + elements_per_vessel);
  b.end_state.resize(2 * static_cast<std::size_t>(elements));
  const bool tree_form = net.boundaries.empty();
  // Where each entry of the list came from: the tree's outlets, its inlet, or net.boundaries.
  const std::size_t tree_inlet = net.inlet ? net.outlets.size() : static_cast<std::size_t>(-1);
  std::vector<std::int32_t> boundary_at(net.node_count(), -1), outlet_index(b.list.size(), -1);
  std::int32_t outlets = 0;
  for (std::size_t i = 0; i < b.list.size(); ++i) {
    const NodeBoundary c = b.list[i];
    boundary_at[static_cast<std::size_t>(c.node)] = static_cast<std::int32_t>(i);
    if (c.is_outlet()) outlet_index[i] = outlets++;
    b.entering.push_back(c.type == BoundaryType::flow ? c.waveform.mean_value() >= 0 : c.type == BoundaryType::pressure);
    if (!c.is_outlet() && c.waveform.shape != Waveform::Shape::constant && !(c.waveform.period > 0))
      throw InputError((i == tree_inlet ? std::string("inlet") : node_name(static_cast<std::size_t>(c.node))) +
                       ": the waveform needs a positive period");
  }

  // Ends meeting at each node.
  std::vector<std::vector<VesselEnd>> at_node(net.node_count());
  for (std::size_t v = 0; v < n; ++v) {
    at_node[net.from[v]].push_back({static_cast<std::int32_t>(v), first_element[v], false});
    at_node[net.to[v]].push_back({static_cast<std::int32_t>(v), first_element[v] + elements_per_vessel - 1, true});
  }
  // A boundary where other than one vessel ends: the tree form's messages for its inlet and
  // outlets, the general one for node boundaries.
  auto refuse_degree = [&](std::size_t node, std::size_t i) {
    const auto& ends = at_node[node];
    if (i == tree_inlet && !ends.empty())
      throw InputError("inlet: " + name(static_cast<std::size_t>(net.index_of(net.inlet->vessel))) +
                       " does not start at a free node (other vessels meet there)");
    if (i < net.outlets.size() && !ends.empty())
      throw InputError(name(static_cast<std::size_t>(net.outlets[i].vessel)) +
                       " has an outlet but other vessels continue from its end");
    throw SettingError("steady", "hemosolve's pulsatile run takes boundary conditions where one vessel ends; " +
                                     node_name(node) + " joins " + std::to_string(ends.size()) + " vessels; " +
                                     placeholder("steady") + " takes any");
  };
  for (std::size_t node = 0; node < at_node.size(); ++node) {
    const auto& ends = at_node[node];
    const std::int32_t bi = boundary_at[node];
    if (ends.size() != 1) {
      if (bi >= 0) refuse_degree(node, static_cast<std::size_t>(bi));
      if (ends.empty()) continue;
    }
    const bool lumped = std::any_of(ends.begin(), ends.end(), [&](const VesselEnd& e) { return zero_d[e.vessel]; });
    if (ends.size() == 1) {
      const VesselEnd e = ends[0];
      const auto v = static_cast<std::size_t>(e.vessel);
      if (bi < 0) {
        if (!tree_form)
          throw InputError(node_name(node) + ": only " + name(v) +
                           " ends there, and the node has no boundary condition (a flow, a pressure or an outlet)");
        if (e.distal) throw InputError(name(v) + " is terminal but has no outlet");
        throw InputError(name(v) + " starts at " + node_name(node) + ", which no vessel feeds and which is not the inlet");
      }
      if (lumped) continue;  // the 0D vessel's boundary: pulse/lumped_vessels
      const NodeBoundary c = b.list[static_cast<std::size_t>(bi)];
      const auto slot = static_cast<std::int32_t>(b.one_d_boundary.size());
      b.one_d_boundary.push_back(bi);
      if (c.type == BoundaryType::flow) {
        b.flows.push_back({e, bi, slot});
      } else if (c.type == BoundaryType::pressure) {
        b.pressures.push_back({e, bi, slot});
      } else {
        NetworkBoundaries::OutletEnd o;
        o.end = e;
        o.index = outlet_index[static_cast<std::size_t>(bi)];
        o.boundary = bi;
        o.slot = slot;
        o.outlet = c.outlet;
        o.outlet.vessel = static_cast<std::int32_t>(v);
        if (o.outlet.type == BoundaryType::rcr && o.outlet.c > 0)
          o.capacitor = static_cast<std::int32_t>(b.capacitors++);
        b.outlets.push_back(o);
      }
      continue;
    }
    if (lumped) {
      for (const VesselEnd& e : ends)
        if (!zero_d[e.vessel]) b.coupled.push_back({e, static_cast<std::int64_t>(node)});
      continue;
    }
    b.junction_ends.insert(b.junction_ends.end(), ends.begin(), ends.end());
    b.junction_offset.push_back(static_cast<std::int64_t>(b.junction_ends.size()));
    b.junction_node.push_back(net.node_id[node]);
  }
  return b;
}

}  // namespace hemotree
