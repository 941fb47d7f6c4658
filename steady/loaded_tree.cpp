#include "steady/loaded_tree.hpp"

#include <algorithm>
#include <span>
#include <stdexcept>
#include <string>

#include "core/errors.hpp"
#include "network_flow/nodal_system.hpp"
#include "formats/network.hpp"
#include "steady/steady_flow.hpp"

namespace hemotree {

TreePotentials solve_loaded_tree(const Network& net, const std::vector<double>& resistance, const TreeLoads& loads) {
  if (net.vessel_count() == 0) throw InputError("the network has no vessels");
  return solve_loaded_tree(net, RunBoundaries(net), resistance, loads);
}

TreePotentials solve_loaded_tree(const Network& net, const RunBoundaries& boundaries,
                                 const std::vector<double>& resistance, const TreeLoads& loads) {
  return LoadedTree(net, boundaries, resistance).solve(loads);
}

LoadedTree::LoadedTree(const Network& net, const RunBoundaries& boundaries,
                       const std::vector<double>& resistance)
    : net_(net), boundaries_(boundaries) {
  const std::size_t n = net.vessel_count(), nodes = net.node_count();
  if (n == 0) throw InputError("the network has no vessels");
  // The run's outlets, by their places in the list.
  for (std::size_t i = 0; i < boundaries.size(); ++i)
    if (boundaries.is_outlet(i)) outlet_boundary_.push_back(static_cast<std::int32_t>(i));
  const std::size_t outlets = outlet_boundary_.size();
  if (resistance.size() != n) throw std::invalid_argument("LoadedTree: resistances not sized to the network");
  if (net.boundaries.empty()) steady_outlets(net);  // the outlets sit on exactly the terminal vessels, none a reflection
  for (std::size_t i = 0; i < boundaries.size(); ++i)
    if (boundaries.type(i) == BoundaryType::reflection)
      throw InputError("node " + std::to_string(net.node_id[static_cast<std::size_t>(boundaries.node(i))]) +
                       ": a reflection outlet has no resistance for the network's response");
  // The nodes a prescribed pressure holds: their disturbance is 0.
  std::vector<unsigned char> held(nodes, 0);
  for (std::size_t i = 0; i < boundaries.size(); ++i)
    if (boundaries.type(i) == BoundaryType::pressure) held[static_cast<std::size_t>(boundaries.node(i))] = 1;

  // The system's nodes: the network's, then a capacitor node per RCR outlet that has one
  // apart from both ends (R1 and R2 both positive). With R1 = 0 the capacitor sits on the
  // vessel's distal node; with R2 = 0 it is grounded (its potential 0, its loads shorted).
  capacitor_node_.assign(outlets, -1);
  std::vector<std::int32_t> a(net.from), b(net.to);
  conductance_.resize(n);
  for (std::size_t v = 0; v < n; ++v) conductance_[v] = 1 / resistance[v];
  if (std::find(held.begin(), held.end(), 1) != held.end()) {
    // A held node is eliminated exactly: a vessel to it is a shunt at its other node (both
    // ends held: nothing), and the node itself stands apart, at 0 (a unit shunt, no current).
    std::vector<std::int32_t> kept_a, kept_b;
    std::vector<double> kept;
    for (std::size_t v = 0; v < n; ++v) {
      const auto i = static_cast<std::size_t>(a[v]), j = static_cast<std::size_t>(b[v]);
      if (held[i] && held[j]) continue;
      if (held[i] || held[j]) {
        held_end_shunt_.emplace_back(static_cast<std::int32_t>(held[i] ? j : i), conductance_[v]);
        continue;
      }
      kept_a.push_back(a[v]);
      kept_b.push_back(b[v]);
      kept.push_back(conductance_[v]);
    }
    a = std::move(kept_a);
    b = std::move(kept_b);
    conductance_ = std::move(kept);
    for (std::size_t i = 0; i < nodes; ++i)
      if (held[i]) grounded_.push_back(static_cast<std::int32_t>(i));
  }
  // A node that no vessel touches is no part of the tree: held at 0 (a unit shunt, no current).
  std::vector<unsigned char> touched(nodes, 0);
  for (std::size_t v = 0; v < n; ++v)
    touched[static_cast<std::size_t>(net.from[v])] = touched[static_cast<std::size_t>(net.to[v])] = 1;
  for (std::size_t i = 0; i < nodes; ++i)
    if (!touched[i]) untouched_.push_back(static_cast<std::int32_t>(i));
  std::size_t size = nodes;
  for (std::size_t k = 0; k < outlets; ++k) {
    const Outlet& o = outlet(k);
    if (o.type == BoundaryType::rcr) rcr_outlets_ = true;
    if (o.type == BoundaryType::rcr && o.r1 != 0 && o.r2 != 0) {
      capacitor_node_[k] = static_cast<std::int32_t>(size++);
      a.push_back(outlet_node(k));
      b.push_back(capacitor_node_[k]);
      conductance_.push_back(1 / o.r1);
    }
  }
  // Forest or not (loops are allowed), the nodal system does the rest.
  system_ = NodalSystem(size, std::move(a), std::move(b));
}

TreePotentials LoadedTree::solve(const TreeLoads& loads) {
  const std::size_t nodes = net_.node_count(), outlets = outlet_boundary_.size();
  const bool no_capacitor_loads = !rcr_outlets_ && loads.capacitor_shunt.empty() && loads.capacitor_current.empty();
  if (loads.node_shunt.size() != nodes || loads.node_current.size() != nodes ||
      (!no_capacitor_loads && (loads.capacitor_shunt.size() != outlets || loads.capacitor_current.size() != outlets)))
    throw std::invalid_argument("LoadedTree: loads not sized to the network");
  // Each node's shunt and current in the order the single solve had always added them: the
  // loads, the vessels to held nodes, the held and the untouched nodes, the outlets. The
  // shunts go straight into the system's workspace (a capacitor node's at its place there).
  const std::span<double> shunt = system_.shunt_workspace();
  std::copy(loads.node_shunt.begin(), loads.node_shunt.end(), shunt.begin());
  std::vector<double> current;
  current.reserve(system_.node_count());
  current = loads.node_current;
  for (const auto& [node, g] : held_end_shunt_) shunt[static_cast<std::size_t>(node)] += g;
  for (const auto* fixed : {&grounded_, &untouched_})
    for (const std::int32_t node : *fixed) {
      shunt[static_cast<std::size_t>(node)] = 1;
      current[static_cast<std::size_t>(node)] = 0;
    }
  for (std::size_t k = 0; k < outlets; ++k) {
    const Outlet& o = outlet(k);
    const auto d = static_cast<std::size_t>(outlet_node(k));  // the tree form's: its vessel's `to`
    if (o.type != BoundaryType::rcr) {
      shunt[d] += 1 / o.r;
    } else if (o.r1 == 0) {
      shunt[d] += 1 / o.r2 + loads.capacitor_shunt[k];
      current[d] += loads.capacitor_current[k];
    } else if (o.r2 == 0) {
      shunt[d] += 1 / o.r1;
    } else {
      shunt[static_cast<std::size_t>(capacitor_node_[k])] = 1 / o.r2 + loads.capacitor_shunt[k];
      current.push_back(loads.capacitor_current[k]);
    }
  }
  // The inlet is open: no conductance to ground there but the node's own load. A component
  // is named by its lowest node, never a capacitor node (numbered after the network's, each
  // joined to one of them).
  const std::int64_t singular = system_.factorize_in_place(conductance_);
  if (singular >= 0)
    throw InputError("node " + std::to_string(net_.node_id[static_cast<std::size_t>(singular)]) +
                     ": no path to ground (no outlet or load conductance in its part of the network)");
  system_.solve(current, current);

  TreePotentials p;
  p.capacitor.assign(outlets, 0.0);
  for (std::size_t k = 0; k < outlets; ++k) {
    const Outlet& o = outlet(k);
    if (capacitor_node_[k] >= 0) p.capacitor[k] = current[static_cast<std::size_t>(capacitor_node_[k])];
    else if (o.type == BoundaryType::rcr && o.r1 == 0) p.capacitor[k] = current[static_cast<std::size_t>(outlet_node(k))];
  }
  current.resize(nodes);  // the network's nodes come first
  p.node = std::move(current);
  return p;
}

}  // namespace hemotree
