#include "solver/loaded_tree.hpp"

#include <stdexcept>
#include <string>

#include "cli/errors.hpp"
#include "network_flow/nodal_system.hpp"
#include "solver/steady_flow.hpp"

namespace hemotree {

TreePotentials solve_loaded_tree(const Network& net, const std::vector<double>& resistance, const TreeLoads& loads) {
  const std::size_t n = net.vessel_count(), nodes = net.node_count();
  if (n == 0) throw InputError("the network has no vessels");
  if (resistance.size() != n || loads.node_shunt.size() != nodes || loads.node_current.size() != nodes ||
      loads.capacitor_shunt.size() != net.outlets.size() || loads.capacitor_current.size() != net.outlets.size())
    throw std::invalid_argument("solve_loaded_tree: resistances or loads not sized to the network");
  steady_outlets(net);  // the outlets sit on exactly the terminal vessels, none a reflection

  // The system's nodes: the network's, then a capacitor node per RCR outlet that has one
  // apart from both ends (R1 and R2 both positive). With R1 = 0 the capacitor sits on the
  // vessel's distal node; with R2 = 0 it is grounded (its potential 0, its loads shorted).
  std::vector<std::int32_t> capacitor_node(net.outlets.size(), -1);
  std::vector<std::int32_t> a(net.from), b(net.to);
  std::vector<double> conductance(n), shunt(loads.node_shunt), current(loads.node_current);
  for (std::size_t v = 0; v < n; ++v) conductance[v] = 1 / resistance[v];
  // A node that no vessel touches is no part of the tree: held at 0 (a unit shunt, no current).
  std::vector<unsigned char> touched(nodes, 0);
  for (std::size_t v = 0; v < n; ++v) touched[static_cast<std::size_t>(a[v])] = touched[static_cast<std::size_t>(b[v])] = 1;
  for (std::size_t i = 0; i < nodes; ++i)
    if (!touched[i]) {
      shunt[i] = 1;
      current[i] = 0;
    }
  for (std::size_t k = 0; k < net.outlets.size(); ++k) {
    const Outlet& o = net.outlets[k];
    const std::int32_t distal = net.to[static_cast<std::size_t>(o.vessel)];
    const auto d = static_cast<std::size_t>(distal);
    if (o.type != OutletType::rcr) {
      shunt[d] += 1 / o.r;
    } else if (o.r1 == 0) {
      shunt[d] += 1 / o.r2 + loads.capacitor_shunt[k];
      current[d] += loads.capacitor_current[k];
    } else if (o.r2 == 0) {
      shunt[d] += 1 / o.r1;
    } else {
      capacitor_node[k] = static_cast<std::int32_t>(shunt.size());
      a.push_back(distal);
      b.push_back(capacitor_node[k]);
      conductance.push_back(1 / o.r1);
      shunt.push_back(1 / o.r2 + loads.capacitor_shunt[k]);
      current.push_back(loads.capacitor_current[k]);
    }
  }

  // Forest or not (loops are allowed), the nodal system does the rest; the inlet is open: no
  // conductance to ground there but the node's own load.
  NodalSystem system(shunt.size(), std::move(a), std::move(b));
  // A component is named by its lowest node, never a capacitor node (numbered after the
  // network's, each joined to one of them).
  const std::int64_t singular = system.factorize(conductance, shunt);
  if (singular >= 0)
    throw InputError("node " + std::to_string(net.node_id[static_cast<std::size_t>(singular)]) +
                     ": no path to ground (no outlet or load conductance in its part of the network)");
  system.solve(current, current);

  TreePotentials p;
  p.node.assign(current.begin(), current.begin() + static_cast<std::ptrdiff_t>(nodes));
  p.capacitor.assign(net.outlets.size(), 0.0);
  for (std::size_t k = 0; k < net.outlets.size(); ++k) {
    const Outlet& o = net.outlets[k];
    if (capacitor_node[k] >= 0) p.capacitor[k] = current[static_cast<std::size_t>(capacitor_node[k])];
    else if (o.type == OutletType::rcr && o.r1 == 0) p.capacitor[k] = p.node[static_cast<std::size_t>(net.to[static_cast<std::size_t>(o.vessel)])];
  }
  return p;
}

}  // namespace hemotree
