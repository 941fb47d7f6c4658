#include "steady/steady_hematocrit.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "core/errors.hpp"
#include "formats/run_boundaries.hpp"
#include "physics/phase_separation.hpp"
#include "physics/poiseuille.hpp"
#include "physics/rheology.hpp"

namespace hemotree {

namespace {

// The vessels at every node (compressed rows): start[n] .. start[n + 1] in `vessel`.
struct Incidence {
  std::vector<std::size_t> start;
  std::vector<std::size_t> vessel;
};

Incidence incidence(const Network& net) {
  Incidence inc;
  inc.start.assign(net.node_count() + 1, 0);
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    ++inc.start[static_cast<std::size_t>(net.from[v]) + 1];
    ++inc.start[static_cast<std::size_t>(net.to[v]) + 1];
  }
  for (std::size_t n = 0; n < net.node_count(); ++n) inc.start[n + 1] += inc.start[n];
  inc.vessel.resize(inc.start.back());
  std::vector<std::size_t> fill(inc.start.begin(), inc.start.end() - 1);
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    inc.vessel[fill[static_cast<std::size_t>(net.from[v])]++] = v;
    inc.vessel[fill[static_cast<std::size_t>(net.to[v])]++] = v;
  }
  return inc;
}

// The node a vessel's flow leaves from and the one it enters.
std::size_t upstream(const Network& net, std::size_t v, double q) {
  return static_cast<std::size_t>(q > 0 ? net.from[v] : net.to[v]);
}
std::size_t downstream(const Network& net, std::size_t v, double q) {
  return static_cast<std::size_t>(q > 0 ? net.to[v] : net.from[v]);
}

// The vessel's lumen where it meets node n.
double diameter_at(const Network& net, std::size_t v, std::size_t n) {
  return static_cast<std::size_t>(net.to[v]) == n ? net.diameter_at_to(v) : net.diameter[v];
}

// Kahn's algorithm on the flow directions; a leftover node lies on or below a directed cycle,
// and walking upstream from it through unvisited nodes must close one.
std::vector<std::size_t> flow_order(const Network& net, const Incidence& inc, std::span<const double> flow) {
  const std::size_t nodes = net.node_count();
  std::vector<std::size_t> pending(nodes, 0);  // inflowing vessels not yet visited
  for (std::size_t v = 0; v < net.vessel_count(); ++v)
    if (flow[v] != 0) ++pending[downstream(net, v, flow[v])];
  std::vector<std::size_t> order;
  order.reserve(nodes);
  for (std::size_t n = 0; n < nodes; ++n)
    if (pending[n] == 0) order.push_back(n);
  for (std::size_t k = 0; k < order.size(); ++k) {
    const std::size_t n = order[k];
    for (std::size_t i = inc.start[n]; i < inc.start[n + 1]; ++i) {
      const std::size_t v = inc.vessel[i];
      if (flow[v] == 0 || upstream(net, v, flow[v]) != n) continue;
      const std::size_t d = downstream(net, v, flow[v]);
      if (--pending[d] == 0) order.push_back(d);
    }
  }
  if (order.size() == nodes) return order;
  std::size_t n = 0;
  while (pending[n] == 0) ++n;
  std::vector<char> seen(nodes, 0);
  for (;;) {
    seen[n] = 1;
    for (std::size_t i = inc.start[n]; i < inc.start[n + 1]; ++i) {
      const std::size_t v = inc.vessel[i];
      if (flow[v] == 0 || downstream(net, v, flow[v]) != n) continue;
      const std::size_t u = upstream(net, v, flow[v]);
      if (pending[u] == 0) continue;  // visited: not on the cycle
      if (seen[u])
        throw InputError("vessel " + std::to_string(net.id[v]) +
                         ": the flows form a directed cycle through it (a circulation with no pressure drop "
                         "to drive it); hematocrits need flows that a pressure field drives");
      n = u;
      break;
    }
  }
}

}  // namespace

std::vector<double> distribute_hematocrit(const Network& net, std::span<const double> flow,
                                          double default_hematocrit, double diameter_scale) {
  const std::size_t vessels = net.vessel_count();
  if (flow.size() != vessels)
    throw InputError("distribute_hematocrit: " + std::to_string(flow.size()) + " flows for " +
                     std::to_string(vessels) + " vessels");
  for (std::size_t v = 0; v < vessels; ++v)
    if (!std::isfinite(flow[v]))
      throw InputError("vessel " + std::to_string(net.id[v]) + ": the flow is not finite");

  std::vector<double> boundary_hematocrit(net.node_count(), std::numeric_limits<double>::quiet_NaN());
  std::vector<char> has_boundary(net.node_count(), 0);
  // Each node's own entry, whatever the order: the run's view (a tree's outlets not copied).
  for (const NodeBoundary& b : RunBoundaries(net)) {
    has_boundary[static_cast<std::size_t>(b.node)] = 1;
    boundary_hematocrit[static_cast<std::size_t>(b.node)] =
        std::isnan(b.hematocrit) ? default_hematocrit : b.hematocrit;
  }

  const Incidence inc = incidence(net);
  std::vector<double> h(vessels, 0.0);  // a stagnant vessel keeps 0: plasma
  std::vector<double> in_q, in_h;
  std::vector<std::size_t> in_v, out_v;
  for (const std::size_t n : flow_order(net, inc, flow)) {
    in_q.clear();
    in_h.clear();
    in_v.clear();
    out_v.clear();
    double surplus = 0;  // vessels' outflow minus inflow: what the boundary supplies
    for (std::size_t i = inc.start[n]; i < inc.start[n + 1]; ++i) {
      const std::size_t v = inc.vessel[i];
      if (flow[v] == 0) continue;
      if (downstream(net, v, flow[v]) == n) {
        in_v.push_back(v);
        in_q.push_back(std::abs(flow[v]));
        in_h.push_back(h[v]);
        surplus -= std::abs(flow[v]);
      } else {
        out_v.push_back(v);
        surplus += std::abs(flow[v]);
      }
    }
    if (out_v.empty()) continue;
    if (has_boundary[n] && surplus > 0) {
      in_q.push_back(surplus);
      in_h.push_back(boundary_hematocrit[n]);
    }
    try {
      if (!has_boundary[n] && in_v.size() == 1 && out_v.size() == 2) {
        const std::size_t f = in_v[0], a = out_v[0], b = out_v[1];
        const double qa = std::abs(flow[a]), qb = std::abs(flow[b]);
        Bifurcation bif;
        bif.feed_diameter = diameter_at(net, f, n);
        bif.first_diameter = diameter_at(net, a, n);
        bif.second_diameter = diameter_at(net, b, n);
        bif.flow_fraction = qa / (qa + qb);
        bif.feed_hematocrit = h[f];
        bif.diameter_scale = diameter_scale;
        const DaughterHematocrits d = daughter_hematocrits(bif);
        h[a] = d.first;
        h[b] = d.second;
      } else {
        const double mix = mixed_hematocrit(in_q, in_h);
        for (const std::size_t v : out_v) h[v] = mix;
      }
    } catch (const InputError& e) {
      throw InputError("node " + std::to_string(net.node_id[n]) + ": " + e.what());
    }
  }
  return h;
}

namespace {

// A vessel whose ends' pressures agree to within round-off of the network's pressures carries
// no flow: in a part where nothing flows (a closed branch, a detached vessel, zero boundary
// flows) the solve leaves flows of 1e-25 m^3/s whose signs are noise, and red cells sent
// along them flipped from pass to pass and never settled. They are set to zero, which the
// distribution reads as no flow.
void settle_round_off_flows(const Network& net, SteadyFlow& s) {
  double pressure_scale = 0;
  for (const double p : s.node_pressure) pressure_scale = std::max(pressure_scale, std::abs(p));
  const double round_off = 1e-12 * pressure_scale;
  for (std::size_t v = 0; v < s.flow.size(); ++v) {
    const double drop = s.node_pressure[static_cast<std::size_t>(net.from[v])] -
                        s.node_pressure[static_cast<std::size_t>(net.to[v])];
    if (std::abs(drop) <= round_off) s.flow[v] = 0;
  }
}

}  // namespace

void check_phase_separation_settings(int max_iterations, double tolerance, double relaxation) {
  if (max_iterations < 1)
    throw InputError("max_iterations " + std::to_string(max_iterations) + ": must be at least 1");
  if (!(tolerance > 0)) throw InputError("tolerance " + std::to_string(tolerance) + ": must be positive");
  if (!(relaxation > 0 && relaxation <= 1))
    throw InputError("relaxation " + std::to_string(relaxation) + ": accepted range (0, 1]");
}

HematocritPass hematocrit_pass(const Network& net, const Blood& blood, SteadyFlow& s, std::span<const double> h,
                               std::span<const double> previous_flow) {
  settle_round_off_flows(net, s);
  HematocritPass pass;
  pass.target = distribute_hematocrit(net, s.flow, blood.hematocrit, blood.phase_separation_diameter_scale());
  double q_scale = 0;
  for (const double q : s.flow) q_scale = std::max(q_scale, std::abs(q));
  // No previous flow to compare with on the first pass: not converged yet.
  pass.change = previous_flow.empty() ? std::numeric_limits<double>::infinity() : 0.0;
  for (std::size_t v = 0; v < h.size(); ++v) {
    pass.change = std::max(pass.change, std::abs(pass.target[v] - h[v]));
    if (!previous_flow.empty() && q_scale > 0)
      pass.change = std::max(pass.change, std::abs(s.flow[v] - previous_flow[v]) / q_scale);
  }
  return pass;
}

SteadyHematocritResult solve_steady_with_phase_separation(const Network& net, const Blood& blood,
                                                          int max_iterations, double tolerance,
                                                          double relaxation) {
  check_phase_separation_settings(max_iterations, tolerance, relaxation);
  const double inlet_flow = net.inlet ? net.inlet->waveform.mean_value() : 0.0;

  std::vector<double> h(net.vessel_count(), blood.hematocrit);
  std::vector<double> previous_flow;
  SteadyHematocritResult result;
  SteadyFlowSolver system(net);  // its pattern analysed once for every pass
  for (int it = 1; it <= max_iterations; ++it) {
    SteadyFlow s = system.solve(vessel_resistances(net, blood, h), inlet_flow);
    HematocritPass pass = hematocrit_pass(net, blood, s, h, previous_flow);
    result.iterations = it;
    result.change = pass.change;
    result.converged = pass.change < tolerance;
    previous_flow = s.flow;
    result.flow = std::move(s);
    result.hematocrit = std::move(pass.target);
    if (result.converged) break;
    for (std::size_t v = 0; v < h.size(); ++v) h[v] += relaxation * (result.hematocrit[v] - h[v]);
  }
  return result;
}

}  // namespace hemotree
