#include "solver/steady_flow.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <stdexcept>
#include <string>

#include "cli/errors.hpp"
#include "formats/topology.hpp"
#include "network_flow/nodal_system.hpp"
#include "physics/poiseuille.hpp"
#include "physics/rheology.hpp"

namespace hemotree {

std::vector<double> vessel_resistances(const Network& net, const Blood& blood) {
  std::vector<double> r(net.vessel_count());
  for (std::size_t v = 0; v < r.size(); ++v)
    r[v] = poiseuille_resistance(apparent_viscosity(blood, net.diameter[v]), net.length[v],
                                 net.diameter[v], blood.alpha);
  return r;
}

namespace {

struct Reduction {
  std::size_t root = 0;
  Children children;
  std::vector<std::int32_t> order;
  std::vector<Equivalent> beyond;   // beyond each vessel's distal node
  std::vector<Equivalent> through;  // the vessel itself and what lies beyond it
};

Reduction reduce(const Network& net, const std::vector<double>& resistance) {
  Reduction red;
  red.root = check_rooted_tree(net);
  red.children = children_of(net);
  const Children& children = red.children;
  const std::size_t n = net.vessel_count();
  auto name = [&](std::size_t v) { return "vessel " + std::to_string(net.id[v]); };
  if (net.inlet && net.index_of(net.inlet->vessel) != static_cast<std::int64_t>(red.root))
    throw InputError("inlet: vessel " + std::to_string(net.inlet->vessel) + " is not the root");

  // The outlet, if any, at each vessel's distal node.
  std::vector<std::int32_t> outlet_of(n, -1);
  for (std::size_t k = 0; k < net.outlets.size(); ++k) {
    const Outlet& o = net.outlets[k];
    const auto v = static_cast<std::size_t>(o.vessel);
    if (children.offset[v + 1] != children.offset[v])
      throw InputError(name(v) + " has an outlet but is not terminal");
    if (o.type == OutletType::reflection)
      throw InputError(name(v) + ": a reflection outlet has no steady resistance");
    outlet_of[v] = static_cast<std::int32_t>(k);
  }

  // Leaves up: each vessel with everything beyond it as (resistance, pressure).
  red.order = breadth_first_order(children, red.root);
  auto& beyond = red.beyond;
  auto& through = red.through;
  beyond.resize(n);
  through.resize(n);
  for (auto it = red.order.rbegin(); it != red.order.rend(); ++it) {
    const auto v = static_cast<std::size_t>(*it);
    const auto first = children.offset[v], last = children.offset[v + 1];
    if (first == last) {
      if (outlet_of[v] < 0) throw InputError(name(v) + " is terminal but has no outlet");
      const Outlet& o = net.outlets[static_cast<std::size_t>(outlet_of[v])];
      beyond[v] = {o.resistance(), o.p_out};
    } else {
      // Daughters in parallel: conductances add, source pressures average by conductance.
      double conductance = 0, weighted = 0;
      for (auto k = first; k < last; ++k) {
        const Equivalent& d = through[static_cast<std::size_t>(children.index[k])];
        conductance += 1 / d.resistance;
        weighted += d.pressure / d.resistance;
      }
      beyond[v] = {1 / conductance, weighted / conductance};
    }
    through[v] = {resistance[v] + beyond[v].resistance, beyond[v].pressure};
  }
  return red;
}

}  // namespace

std::vector<Equivalent> reduce_beyond(const Network& net, const std::vector<double>& resistance) {
  return reduce(net, resistance).beyond;
}

std::vector<std::int32_t> steady_outlets(const Network& net) {
  const std::size_t n = net.vessel_count();
  auto name = [&](std::size_t v) { return "vessel " + std::to_string(net.id[v]); };
  // A vessel is terminal when no vessel leaves its distal node.
  std::vector<unsigned char> left(net.node_count(), 0);
  for (std::size_t v = 0; v < n; ++v) left[static_cast<std::size_t>(net.from[v])] = 1;
  std::vector<std::int32_t> outlet_of(n, -1);
  for (std::size_t k = 0; k < net.outlets.size(); ++k) {
    const Outlet& o = net.outlets[k];
    if (o.vessel < 0 || static_cast<std::size_t>(o.vessel) >= n)
      throw InputError("outlet " + std::to_string(k) + ": no vessel of index " + std::to_string(o.vessel));
    const auto v = static_cast<std::size_t>(o.vessel);
    if (left[static_cast<std::size_t>(net.to[v])]) throw InputError(name(v) + " has an outlet but is not terminal");
    if (o.type == OutletType::reflection)
      throw InputError(name(v) + ": a reflection outlet has no steady resistance");
    if (!(o.resistance() > 0)) throw InputError(name(v) + ": its outlet has no resistance");
    if (outlet_of[v] >= 0) throw InputError(name(v) + " has two outlets");
    outlet_of[v] = static_cast<std::int32_t>(k);
  }
  for (std::size_t v = 0; v < n; ++v)
    if (!left[static_cast<std::size_t>(net.to[v])] && outlet_of[v] < 0)
      throw InputError(name(v) + " is terminal but has no outlet");
  return outlet_of;
}

namespace {

// The steady flow as the nodal system of the network's node pressures (nodal_system.hpp):
// each vessel an edge of conductance 1/R, each outlet a shunt 1/R to its outflow pressure at
// its vessel's distal node (b += p_out / R), the inflow injected at the inlet's node. The
// graph, the outlets and the checks are set once; every solve refactorises (the distended
// iteration changes the resistances each sweep).
class SteadySystem {
 public:
  explicit SteadySystem(const Network& net);
  SteadyFlow solve(const std::vector<double>& resistance, double inlet_flow);

 private:
  const Network& net_;
  std::size_t inlet_node_ = 0;
  NodalSystem system_;
  std::vector<double> shunt_, outlet_current_;  // per node: the outlets' 1/R and p_out / R
  std::vector<double> conductance_;             // per vessel
};

SteadySystem::SteadySystem(const Network& net) : net_(net) {
  const std::size_t n = net.vessel_count(), nodes = net.node_count();
  auto name = [&](std::size_t v) { return "vessel " + std::to_string(net.id[v]); };
  if (n == 0) throw InputError("the network has no vessels");
  steady_outlets(net);  // the outlets sit on exactly the terminal vessels, none a reflection

  // The inlet: the network's, or else the one vessel that no vessel feeds. Its node is the
  // network's only open proximal end: any other node that no vessel enters would be an end
  // with neither inflow nor outlet.
  std::vector<std::int32_t> entering(nodes, -1);
  for (std::size_t v = 0; v < n; ++v) entering[static_cast<std::size_t>(net.to[v])] = static_cast<std::int32_t>(v);
  std::int64_t inlet = -1;
  if (net.inlet) {
    inlet = net.index_of(net.inlet->vessel);
    if (inlet < 0) throw InputError("inlet: no vessel " + std::to_string(net.inlet->vessel));
    const std::int32_t feeder = entering[static_cast<std::size_t>(net.from[static_cast<std::size_t>(inlet)])];
    if (feeder >= 0)
      throw InputError("inlet: vessel " + std::to_string(net.inlet->vessel) + " is not a root (" +
                       name(static_cast<std::size_t>(feeder)) + " ends at its 'from' node)");
  } else {
    for (std::size_t v = 0; v < n; ++v) {
      if (entering[static_cast<std::size_t>(net.from[v])] >= 0) continue;
      if (inlet >= 0 && net.from[v] != net.from[static_cast<std::size_t>(inlet)])
        throw InputError("no inlet given, and " + name(static_cast<std::size_t>(inlet)) + " and " + name(v) +
                         " are both fed by no vessel");
      if (inlet < 0) inlet = static_cast<std::int64_t>(v);
    }
    if (inlet < 0) throw InputError("no inlet given, and every vessel is fed by another (a closed loop)");
  }
  inlet_node_ = static_cast<std::size_t>(net.from[static_cast<std::size_t>(inlet)]);
  for (std::size_t v = 0; v < n; ++v) {
    const auto from = static_cast<std::size_t>(net.from[v]);
    if (entering[from] < 0 && from != inlet_node_)
      throw InputError(name(v) + " is fed by no vessel and does not start at the inlet (vessel " +
                       std::to_string(net.id[static_cast<std::size_t>(inlet)]) + ")");
  }

  shunt_.assign(nodes, 0.0);
  outlet_current_.assign(nodes, 0.0);
  for (const Outlet& o : net.outlets) {
    const auto node = static_cast<std::size_t>(net.to[static_cast<std::size_t>(o.vessel)]);
    shunt_[node] += 1 / o.resistance();
    outlet_current_[node] += o.p_out / o.resistance();
  }
  // A node that no vessel touches carries nothing: a unit shunt holds it at 0 Pa.
  std::vector<unsigned char> touched(nodes, 0);
  for (std::size_t v = 0; v < n; ++v) touched[static_cast<std::size_t>(net.from[v])] = touched[static_cast<std::size_t>(net.to[v])] = 1;
  std::size_t untouched = 0;
  for (std::size_t i = 0; i < nodes; ++i)
    if (!touched[i]) {
      shunt_[i] = 1;
      ++untouched;
    }
  system_ = NodalSystem(nodes, net.from, net.to);

  // Every vessel must hang together with the inlet: a part apart from it would carry no flow
  // (or, with no outlet, have no solution at all). A forest has nodes - edges components, so a
  // tree needs no search; otherwise union-find (keeping the lower root: short paths on a
  // network numbered from its root) names the first vessel apart.
  if (system_.method() != NodalSystem::Method::tree_elimination || nodes - n != 1 + untouched) {
    std::vector<std::int32_t> up(nodes);
    std::iota(up.begin(), up.end(), 0);
    auto root = [&](std::int32_t i) {
      while (up[static_cast<std::size_t>(i)] != i) {
        auto& next = up[static_cast<std::size_t>(i)];
        next = up[static_cast<std::size_t>(next)];  // path halving
        i = next;
      }
      return i;
    };
    for (std::size_t v = 0; v < n; ++v) {
      const std::int32_t rf = root(net.from[v]), rt = root(net.to[v]);
      up[static_cast<std::size_t>(std::max(rf, rt))] = std::min(rf, rt);
    }
    const std::int32_t inlet_part = root(static_cast<std::int32_t>(inlet_node_));
    for (std::size_t v = 0; v < n; ++v)
      if (root(net.from[v]) != inlet_part) throw InputError(name(v) + " is not connected to the inlet");
  }
  conductance_.resize(n);
}

SteadyFlow SteadySystem::solve(const std::vector<double>& resistance, double inlet_flow) {
  const std::size_t n = net_.vessel_count();
  if (resistance.size() != n)
    throw std::invalid_argument("solve_steady_flow: " + std::to_string(resistance.size()) + " resistances for " +
                                std::to_string(n) + " vessels");
  for (std::size_t v = 0; v < n; ++v) conductance_[v] = 1 / resistance[v];
  // Connected to the inlet, the network is singular only without a single outlet.
  if (system_.factorize(conductance_, shunt_) >= 0) throw InputError("the network has no outlet for the inflow");
  SteadyFlow s;
  s.node_pressure = outlet_current_;
  s.node_pressure[inlet_node_] += inlet_flow;
  system_.solve(s.node_pressure, s.node_pressure);
  s.inlet_pressure = s.node_pressure[inlet_node_];
  s.flow.resize(n);
  for (std::size_t v = 0; v < n; ++v)
    s.flow[v] = (s.node_pressure[static_cast<std::size_t>(net_.from[v])] -
                 s.node_pressure[static_cast<std::size_t>(net_.to[v])]) / resistance[v];
  return s;
}

}  // namespace

SteadyFlow solve_steady_flow(const Network& net, const std::vector<double>& resistance,
                             double inlet_flow, std::vector<Equivalent>* beyond) {
  SteadyFlow s = SteadySystem(net).solve(resistance, inlet_flow);
  if (beyond) *beyond = reduce_beyond(net, resistance);
  return s;
}

SteadyFlow solve_steady_flow(const Network& net) {
  if (!net.inlet) throw InputError("the network has no inlet");
  const Blood blood = net.blood.value_or(Blood{});
  return solve_steady_flow(net, vessel_resistances(net, blood), net.inlet->waveform.mean_value());
}

SteadyFlow solve_distended_steady_flow(const Network& net, const Blood& blood, std::span<const VesselLaw> laws,
                                       const ViscosityTable& viscosity, double inlet_flow,
                                       std::vector<double>* resistance) {
  std::vector<double> r = vessel_resistances(net, blood);
  SteadySystem system(net);
  SteadyFlow s = system.solve(r, inlet_flow);
  // Each sweep's resistances are averaged with the last ones: the iteration alternates (a
  // higher pressure widens the lumens, which lowers it), and halving the step damps that.
  for (int sweep = 0; sweep < 200; ++sweep) {
    for (std::size_t v = 0; v < r.size(); ++v) {
      const double p = 0.5 * (s.node_pressure[net.from[v]] + s.node_pressure[net.to[v]]);
      const double area = laws[v].area(p);
      if (!(area > 0))
        throw InputError("vessel " + std::to_string(net.id[v]) + ": the lumen collapses in steady flow");
      const double diameter = std::sqrt(4 / std::numbers::pi * area);
      r[v] = 0.5 * (r[v] + poiseuille_resistance(viscosity(area), net.length[v], diameter, blood.alpha));
    }
    SteadyFlow next = system.solve(r, inlet_flow);
    double change = 0;
    for (std::size_t k = 0; k < next.node_pressure.size(); ++k)
      change = std::max(change, std::abs(next.node_pressure[k] - s.node_pressure[k]));
    s = std::move(next);
    if (change <= 1e-9 * std::abs(s.inlet_pressure)) break;
  }
  if (resistance) *resistance = std::move(r);
  return s;
}

}  // namespace hemotree
