#include "steady/steady_flow.hpp"

#include "steady/distended_iteration.hpp"

#include <algorithm>
#include <limits>
#include <memory>
#include <cmath>
#include <numbers>
#include <numeric>
#include <stdexcept>
#include <string>

#include "boundaries/flow_inlet.hpp"
#include "boundaries/pressure_end.hpp"
#include "boundaries/rcr_outlet.hpp"
#include "boundaries/resistance_outlet.hpp"
#include "boundaries/system_rows.hpp"
#include "core/errors.hpp"
#include "core/parallel_errors.hpp"
#include "core/setting_error.hpp"
#include "formats/run_boundaries.hpp"
#include "formats/connected_parts.hpp"
#include "formats/topology.hpp"
#include "network_flow/flow_network.hpp"
#include "physics/poiseuille.hpp"
#include "physics/rheology.hpp"

namespace hemotree {

std::vector<double> vessel_resistances(const Network& net, const Blood& blood) {
  return vessel_resistances(net, blood, {});
}

double vessel_resistance(const Network& net, const Blood& blood, std::size_t v) {
  return net.is_tapered(v)
             ? tapered_poiseuille_resistance([&](double d) { return apparent_viscosity(blood, d); }, net.length[v],
                                             net.diameter[v], net.distal_diameter[v], blood.alpha)
             : poiseuille_resistance(apparent_viscosity(blood, net.diameter[v]), net.length[v], net.diameter[v],
                                     blood.alpha);
}

double vessel_resistance(const Network& net, const Blood& blood, std::size_t v, std::span<const double> hematocrit) {
  if (hematocrit.empty()) return vessel_resistance(net, blood, v);
  Blood own = blood;
  own.hematocrit = hematocrit[v];
  return vessel_resistance(net, own, v);
}

std::vector<double> vessel_resistances(const Network& net, const Blood& blood, std::span<const double> hematocrit,
                                       int threads) {
  std::vector<double> r(net.vessel_count());
  parallel_blocks(static_cast<std::int64_t>(r.size()), threads, [&](std::int64_t first, std::int64_t last) {
    for (auto v = static_cast<std::size_t>(first); v < static_cast<std::size_t>(last); ++v)
      r[v] = vessel_resistance(net, blood, v, hematocrit);
  });
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
    if (o.type == BoundaryType::reflection)
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
    if (o.type == BoundaryType::reflection)
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

// Each condition's row (boundaries/), the tree's inflow left to solve()'s inlet_flow.
template <class Conditions>
void add_rows(const Network& net, const Conditions& conditions, SteadyRows& out) {
  if (net.inlet) out.inlet_node = net.from[static_cast<std::size_t>(net.index_of(net.inlet->vessel))];
  NodalRows rows{out.shunt, out.inflow, out.pressure, out.prescribed};
  for (const NodeBoundary& b : conditions) {
    const auto i = static_cast<std::size_t>(b.node);
    switch (b.type) {
      case BoundaryType::flow:
        if (static_cast<std::int64_t>(i) != out.inlet_node) FlowInlet{b.waveform.mean_value()}.add_steady_row(rows, i);
        break;
      case BoundaryType::pressure:
        PressureEnd{b.waveform.mean_value()}.add_steady_row(rows, i);
        break;
      case BoundaryType::rcr:
      case BoundaryType::resistance:  // the outlet's parameters are of its own type
        if (b.outlet.type == BoundaryType::rcr)
          RcrOutlet{b.outlet.r1, b.outlet.c, b.outlet.r2, b.outlet.p_out}.add_steady_row(rows, i);
        else
          ResistanceOutlet{b.outlet.r, b.outlet.p_out}.add_steady_row(rows, i);
        break;
      case BoundaryType::reflection: break;  // no steady row: refused by the checks
    }
  }
}

// The checks of a tree's boundaries (an inlet, outlets on its terminal vessels); without a
// given inlet, the one vessel no vessel feeds names its node.
void check_tree_form(const Network& net, SteadyRows& rows);
// The checks of boundaries at nodes: every dead end, every part without a pressure reference.
void check_node_form(const Network& net, const std::vector<NodeBoundary>& boundaries);

}  // namespace

void refuse_floating_part(const Network& net, std::int64_t node) {
  if (net.boundaries.empty()) throw InputError("the network has no outlet for the inflow");
  // The checks found a reference in every part: this one's is lost in rounding.
  throw InputError("node " + std::to_string(net.node_id[static_cast<std::size_t>(node)]) +
                   ": the outlets' resistances of its part are too large against its vessels' to fix its pressure");
}

SteadyRows steady_rows(const Network& net) {
  const std::size_t n = net.vessel_count(), nodes = net.node_count();
  if (n == 0) throw InputError("the network has no vessels");
  SteadyRows rows;
  rows.shunt.assign(nodes, 0.0);
  rows.inflow.assign(nodes, 0.0);
  rows.pressure.assign(nodes, 0.0);
  rows.prescribed.assign(nodes, 0);
  // A tree's boundaries (an inlet, outlets on its terminal vessels) keep the tree's checks
  // and messages; boundaries at nodes make any connected graph solvable.
  if (net.boundaries.empty()) {
    check_tree_form(net, rows);
    // A view (formats/run_boundaries.hpp): a tree's two million outlets are not copied as
    // conditions (twice over where node_boundaries sorts them: the run's set-up peak). One
    // condition per node, each adding to its own node's row: the order does not matter.
    add_rows(net, RunBoundaries(net), rows);
  } else {
    const std::vector<NodeBoundary> boundaries = node_boundaries(net);
    check_node_form(net, boundaries);
    add_rows(net, boundaries, rows);
  }
  // A node that no vessel touches carries nothing: a unit shunt holds it at 0 Pa.
  std::vector<unsigned char> touched(nodes, 0);
  for (std::size_t v = 0; v < n; ++v) touched[static_cast<std::size_t>(net.from[v])] = touched[static_cast<std::size_t>(net.to[v])] = 1;
  for (std::size_t i = 0; i < nodes; ++i)
    if (!touched[i] && !rows.prescribed[i]) rows.shunt[i] = 1;
  return rows;
}

SteadyRows boundary_rows(const Network& part) {
  SteadyRows rows;
  rows.shunt.assign(part.node_count(), 0.0);
  rows.inflow.assign(part.node_count(), 0.0);
  rows.pressure.assign(part.node_count(), 0.0);
  rows.prescribed.assign(part.node_count(), 0);
  if (part.boundaries.empty())
    add_rows(part, RunBoundaries(part), rows);
  else
    add_rows(part, node_boundaries(part), rows);
  return rows;
}

SteadyFlowSolver::SteadyFlowSolver(const Network& net) : net_(net), rows_(steady_rows(net)) {
  system_ = std::make_unique<FlowNetwork>(net.node_count(), net.from, net.to, rows_.prescribed);
  conductance_.resize(net.vessel_count());
}

SteadyFlowSolver::~SteadyFlowSolver() = default;

SteadyFlow SteadyFlowSolver::solve(const std::vector<double>& resistance, double inlet_flow) {
  SteadyFlow s;
  solve(resistance, inlet_flow, s);
  return s;
}

void SteadyFlowSolver::set_threads(int threads) { system_->set_threads(threads); }

namespace {

void check_tree_form(const Network& net, SteadyRows& rows) {
  const std::size_t n = net.vessel_count(), nodes = net.node_count();
  auto name = [&](std::size_t v) { return "vessel " + std::to_string(net.id[v]); };
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
  const auto inlet_node = static_cast<std::size_t>(net.from[static_cast<std::size_t>(inlet)]);
  for (std::size_t v = 0; v < n; ++v) {
    const auto from = static_cast<std::size_t>(net.from[v]);
    if (entering[from] < 0 && from != inlet_node)
      throw InputError(name(v) + " is fed by no vessel and does not start at the inlet (vessel " +
                       std::to_string(net.id[static_cast<std::size_t>(inlet)]) + ")");
  }
  if (!net.inlet) rows.inlet_node = static_cast<std::int64_t>(inlet_node);

  // Every vessel must hang together with the inlet: a part apart from it would carry no flow
  // (or, with no outlet, have no solution at all).
  NodeParts parts(net);
  const std::int32_t inlet_part = parts.root(static_cast<std::int32_t>(inlet_node));
  for (std::size_t v = 0; v < n; ++v)
    if (parts.root(net.from[v]) != inlet_part) throw InputError(name(v) + " is not connected to the inlet");
}

void check_node_form(const Network& net, const std::vector<NodeBoundary>& boundaries) {
  const std::size_t n = net.vessel_count(), nodes = net.node_count();
  auto node_name = [&](std::int64_t i) { return "node " + std::to_string(net.node_id[static_cast<std::size_t>(i)]); };
  std::vector<std::int32_t> degree(nodes, 0), some_vessel(nodes, -1);
  for (std::size_t v = 0; v < n; ++v)
    for (const std::int32_t i : {net.from[v], net.to[v]}) {
      ++degree[static_cast<std::size_t>(i)];
      some_vessel[static_cast<std::size_t>(i)] = static_cast<std::int32_t>(v);
    }
  std::vector<unsigned char> has_boundary(nodes, 0);
  for (const NodeBoundary& b : boundaries) {
    if (degree[static_cast<std::size_t>(b.node)] == 0)
      throw InputError(node_name(b.node) + " has a " + std::string(to_string(b.type)) +
                       " boundary but no vessel meets it");
    if (b.type == BoundaryType::reflection)
      throw InputError(node_name(b.node) + ": a reflection outlet has no steady resistance (give an R or RCR)");
    if (b.is_outlet() && !(b.outlet.resistance() > 0))
      throw InputError(node_name(b.node) + ": its outlet has no resistance");
    has_boundary[static_cast<std::size_t>(b.node)] = 1;
  }
  // Every dead end at once, the first named in full: a measured network's fragments end in
  // many, and finding them one run at a time is what a user should not have to do.
  std::vector<std::size_t> dead_ends;
  for (std::size_t i = 0; i < nodes; ++i)
    if (degree[i] == 1 && !has_boundary[i]) dead_ends.push_back(i);
  if (!dead_ends.empty()) {
    const std::size_t i = dead_ends.front(), shown = 5;
    std::string others;
    for (std::size_t k = 1; k < dead_ends.size() && k <= shown; ++k)
      others += (k > 1 ? ", " : "") + std::to_string(net.node_id[dead_ends[k]]);
    if (dead_ends.size() > shown + 1) others += " and " + std::to_string(dead_ends.size() - shown - 1) + " more";
    throw InputError("vessel " + std::to_string(net.id[static_cast<std::size_t>(some_vessel[i])]) + " ends at " +
                     node_name(static_cast<std::int64_t>(i)) +
                     ", which no other vessel meets and which has no boundary condition (a dead end; a "
                     "closed one is {\"node\": " + std::to_string(net.node_id[i]) + ", \"type\": \"flow\", \"flow\": 0})" +
                     (dead_ends.size() > 1 ? "; " + std::to_string(dead_ends.size() - 1) + " more dead end" +
                                                 (dead_ends.size() > 2 ? "s" : "") + ", at node" +
                                                 (dead_ends.size() > 2 ? "s " : " ") + others
                                           : std::string()));
  }
  // Each connected part needs a pressure to refer to: a prescribed one or an outlet's. All
  // parts without one are named at once: a measured network has many fragments.
  if (const std::string refusal = pressure_reference_refusal(net, boundaries); !refusal.empty())
    throw SettingError("pressure_at", refusal);
}

}  // namespace

void SteadyFlowSolver::solve(const std::vector<double>& resistance, double inlet_flow, SteadyFlow& s) {
  const std::size_t n = net_.vessel_count();
  if (resistance.size() != n)
    throw std::invalid_argument("solve_steady_flow: " + std::to_string(resistance.size()) + " resistances for " +
                                std::to_string(n) + " vessels");
  for (std::size_t v = 0; v < n; ++v) conductance_[v] = 1 / resistance[v];
  const std::int64_t floating = system_->factorize(conductance_, rows_.shunt);
  if (floating >= 0) refuse_floating_part(net_, floating);
  s.node_pressure.assign(rows_.pressure.begin(), rows_.pressure.end());
  std::vector<double>& inflow = inflow_with_inlet_;
  inflow.assign(rows_.inflow.begin(), rows_.inflow.end());
  if (rows_.inlet_node >= 0) inflow[static_cast<std::size_t>(rows_.inlet_node)] += inlet_flow;
  system_->solve(inflow, s.node_pressure);
  s.inlet_pressure = rows_.inlet_node >= 0 ? s.node_pressure[static_cast<std::size_t>(rows_.inlet_node)]
                                      : std::numeric_limits<double>::quiet_NaN();
  s.flow.resize(n);
  for (std::size_t v = 0; v < n; ++v)
    s.flow[v] = (s.node_pressure[static_cast<std::size_t>(net_.from[v])] -
                 s.node_pressure[static_cast<std::size_t>(net_.to[v])]) / resistance[v];
}

SteadyFlow solve_steady_flow(const Network& net, const std::vector<double>& resistance,
                             double inlet_flow, std::vector<Equivalent>* beyond) {
  SteadyFlow s = SteadyFlowSolver(net).solve(resistance, inlet_flow);
  if (beyond) *beyond = reduce_beyond(net, resistance);
  return s;
}

SteadyFlow solve_steady_flow(const Network& net) {
  if (!net.inlet && net.boundaries.empty()) throw InputError("the network has no inlet and no boundary conditions");
  const Blood blood = net.blood.value_or(Blood{});
  return solve_steady_flow(net, vessel_resistances(net, blood), net.inlet ? net.inlet->waveform.mean_value() : 0.0);
}

SteadyFlow solve_distended_steady_flow(const Network& net, const Blood& blood, std::span<const TubeLaw> laws,
                                       const ViscosityTable& viscosity, double inlet_flow,
                                       std::vector<double>* resistance, int threads) {
  std::vector<double> r = vessel_resistances(net, blood, {}, threads);
  SteadyFlowSolver system(net);
  system.set_threads(threads);
  const DistendedPart whole{{},
                            {},
                            [&](const std::vector<double>& resistances, SteadyFlow& s) {
                              system.solve(resistances, inlet_flow, s);
                            },
                            [](double x) { return x; },
                            [](const std::function<void()>& step) { step(); }};
  SteadyFlow s = iterate_distended(net, blood, laws, viscosity, whole, r, threads);
  if (resistance) *resistance = std::move(r);
  return s;
}

}  // namespace hemotree
