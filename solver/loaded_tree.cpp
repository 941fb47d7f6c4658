#include "solver/loaded_tree.hpp"

#include <string>

#include "cli/errors.hpp"
#include "formats/topology.hpp"

namespace hemotree {

namespace {
// A Norton source: conductance to ground and the current it drives into its node.
struct Norton {
  double conductance = 0, current = 0;
};
// Through a series resistance: the Thevenin form (E = J / G, R = 1 / G) with r added.
Norton in_series(const Norton& n, double r) {
  const double resistance = 1 / n.conductance + r;
  return {1 / resistance, n.current / n.conductance / resistance};
}
}  // namespace

TreePotentials solve_loaded_tree(const Network& net, const std::vector<double>& resistance, const TreeLoads& loads) {
  const std::size_t root = check_rooted_tree(net);
  const Children children = children_of(net);
  const std::size_t n = net.vessel_count();
  std::vector<std::int32_t> outlet_of(n, -1);
  for (std::size_t k = 0; k < net.outlets.size(); ++k) {
    if (net.outlets[k].type == OutletType::reflection)
      throw InputError("vessel " + std::to_string(net.id[static_cast<std::size_t>(net.outlets[k].vessel)]) +
                       ": a reflection outlet has no steady resistance");
    outlet_of[static_cast<std::size_t>(net.outlets[k].vessel)] = static_cast<std::int32_t>(k);
  }
  // The capacitor node of an RCR outlet: R2 to ground, its shunt and current.
  auto capacitor_node = [&](std::size_t k) {
    const Outlet& o = net.outlets[k];
    return Norton{1 / o.r2 + loads.capacitor_shunt[k], loads.capacitor_current[k]};
  };
  auto outlet_source = [&](std::size_t k) {
    const Outlet& o = net.outlets[k];
    return o.type == OutletType::rcr ? in_series(capacitor_node(k), o.r1) : Norton{1 / o.r, 0};
  };

  // Leaves up: at each vessel's distal node, its own loads with everything beyond in parallel.
  const std::vector<std::int32_t> order = breadth_first_order(children, root);
  std::vector<Norton> distal(n);
  for (auto it = order.rbegin(); it != order.rend(); ++it) {
    const auto v = static_cast<std::size_t>(*it);
    const auto node = static_cast<std::size_t>(net.to[v]);
    Norton at{loads.node_shunt[node], loads.node_current[node]};
    if (children.offset[v] == children.offset[v + 1]) {
      if (outlet_of[v] < 0) throw InputError("vessel " + std::to_string(net.id[v]) + " is terminal but has no outlet");
      const Norton o = outlet_source(static_cast<std::size_t>(outlet_of[v]));
      at.conductance += o.conductance;
      at.current += o.current;
    }
    for (auto k = children.offset[v]; k < children.offset[v + 1]; ++k) {
      const auto d = static_cast<std::size_t>(children.index[k]);
      const Norton through = in_series(distal[d], resistance[d]);
      at.conductance += through.conductance;
      at.current += through.current;
    }
    if (!(at.conductance > 0)) throw InputError("vessel " + std::to_string(net.id[v]) + ": no path to ground");
    distal[v] = at;
  }

  // Root down: the inlet node (open: no current from outside), then every distal node.
  TreePotentials p;
  p.node.assign(net.node_count(), 0.0);
  p.capacitor.assign(net.outlets.size(), 0.0);
  const auto inlet = static_cast<std::size_t>(net.from[root]);
  const Norton through = in_series(distal[root], resistance[root]);
  p.node[inlet] = (through.current + loads.node_current[inlet]) / (through.conductance + loads.node_shunt[inlet]);
  for (const std::int32_t vi : order) {
    const auto v = static_cast<std::size_t>(vi);
    const Norton& at = distal[v];
    // The vessel's current into its distal node, from the potentials at both ends: solve
    // (u - V) / r = G V - J for the distal potential V.
    const double upstream = p.node[static_cast<std::size_t>(net.from[v])];
    const double r = resistance[v];
    const double v_distal = (upstream / r + at.current) / (1 / r + at.conductance);
    p.node[static_cast<std::size_t>(net.to[v])] = v_distal;
    if (outlet_of[v] >= 0) {
      const auto k = static_cast<std::size_t>(outlet_of[v]);
      const Outlet& o = net.outlets[k];
      if (o.type == OutletType::rcr) {
        const Norton c = capacitor_node(k);
        p.capacitor[k] = (v_distal / o.r1 + c.current) / (1 / o.r1 + c.conductance);
      }
    }
  }
  return p;
}

}  // namespace hemotree
