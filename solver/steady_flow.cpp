#include "solver/steady_flow.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "cli/errors.hpp"
#include "formats/topology.hpp"
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

SteadyFlow solve_steady_flow(const Network& net, const std::vector<double>& resistance,
                             double inlet_flow, std::vector<Equivalent>* beyond) {
  Reduction red = reduce(net, resistance);
  const std::size_t root = red.root;
  const std::size_t n = net.vessel_count();
  const Children& children = red.children;
  const auto& through = red.through;
  const auto& order = red.order;

  // Root down: the inlet flow fixes the inlet pressure, then every split.
  SteadyFlow s;
  s.flow.assign(n, 0.0);
  s.node_pressure.assign(net.node_count(), 0.0);
  s.flow[root] = inlet_flow;
  s.inlet_pressure = through[root].pressure + inlet_flow * through[root].resistance;
  s.node_pressure[net.from[root]] = s.inlet_pressure;
  for (const std::int32_t vi : order) {
    const auto v = static_cast<std::size_t>(vi);
    const double p_distal = s.node_pressure[net.from[v]] - s.flow[v] * resistance[v];
    s.node_pressure[net.to[v]] = p_distal;
    for (auto k = children.offset[v]; k < children.offset[v + 1]; ++k) {
      const auto d = static_cast<std::size_t>(children.index[k]);
      s.flow[d] = (p_distal - through[d].pressure) / through[d].resistance;
    }
  }
  if (beyond) *beyond = std::move(red.beyond);
  return s;
}

SteadyFlow solve_steady_flow(const Network& net) {
  if (!net.inlet) throw InputError("the network has no inlet");
  const Blood blood = net.blood.value_or(Blood{});
  return solve_steady_flow(net, vessel_resistances(net, blood), net.inlet->waveform.mean_flow());
}

SteadyFlow solve_distended_steady_flow(const Network& net, const Blood& blood, std::span<const VesselLaw> laws,
                                       const ViscosityTable& viscosity, double inlet_flow,
                                       std::vector<double>* resistance) {
  std::vector<double> r = vessel_resistances(net, blood);
  SteadyFlow s = solve_steady_flow(net, r, inlet_flow);
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
    SteadyFlow next = solve_steady_flow(net, r, inlet_flow);
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
