#include "pulse/lumped_vessels.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "boundaries/pressure_end.hpp"
#include "boundaries/system_rows.hpp"
#include "core/errors.hpp"
#include "core/setting_error.hpp"
#include "core/parallel_errors.hpp"
#include "physics/poiseuille.hpp"
#include "pulse/lumped_order.hpp"
#include "pulse/solution_breakdown.hpp"

namespace hemotree {

LumpedVessels::LumpedVessels(const Network& net, std::span<const TubeLaw> laws, const ViscosityTable& viscosity,
                             const Blood& blood, const std::vector<bool>& zero_d, std::span<const std::int32_t> taper_of,
                             std::span<const VesselTaper> tapers, std::span<const std::uint8_t> sections,
                             const LumpedCut* cut, const LumpedHalo* halo)
    : density_(blood.density), friction_k_(friction_coefficient(blood.alpha)), viscosity_(&viscosity) {
  const std::size_t n = net.vessel_count();
  node_of_.assign(net.node_count(), -1);
  index_of_vessel_.assign(n, -1);
  // Every subtree contiguous (pulse/lumped_order.hpp): the elimination's tasks stream.
  LumpedOrder order = cut ? cut->order : halo ? halo->order : subtree_lumped_order(net, zero_d);
  for (std::size_t k = 0; k < order.nodes.size(); ++k)
    node_of_[static_cast<std::size_t>(order.nodes[k])] = static_cast<std::int32_t>(k);
  auto sections_of = [&](std::size_t v) {
    const bool is_tapered = !taper_of.empty() && taper_of[v] >= 0;
    return sections.empty() || is_tapered ? std::size_t{1} : std::max<std::size_t>(sections[v], 1);
  };
  // The inner nodes of vessels in sections, numbered in the network's order of their vessels
  // (a checkpoint's order; placed after the capacitors below): here ~j for the j-th. (Not over
  // ranks: pulse/lumped_cut.hpp.)
  std::vector<std::int32_t> inner_first;
  std::int32_t inner = 0;
  if (!sections.empty()) {
    inner_first.assign(n, -1);
    for (std::size_t v = 0; v < n; ++v)
      if (zero_d[v] && sections_of(v) > 1) {
        inner_first[v] = inner;
        inner += static_cast<std::int32_t>(sections_of(v) - 1);
      }
    if (inner > 0) first_edge_.push_back(0);
  }
  for (const std::int32_t vessel : order.vessels) {
    const auto v = static_cast<std::size_t>(vessel);
    index_of_vessel_[v] = static_cast<std::int32_t>(vessels_.size());
    vessels_.push_back(vessel);
    const std::size_t count = sections_of(v);
    const TubeLaw& law = laws[v];
    for (std::size_t s = 0; s < count; ++s) {
      a_.push_back(s == 0 ? node_of_[static_cast<std::size_t>(net.from[v])] : ~(inner_first[v] + static_cast<std::int32_t>(s) - 1));
      b_.push_back(s + 1 == count ? node_of_[static_cast<std::size_t>(net.to[v])] : ~(inner_first[v] + static_cast<std::int32_t>(s)));
      edge_length_.push_back(count == 1 ? net.length[v] : net.length[v] / static_cast<double>(count));
      edge_root_slope_.push_back(law.lumen_root_slope());
      edge_root_intercept_.push_back(law.lumen_root_intercept());
    }
    if (!first_edge_.empty()) first_edge_.push_back(static_cast<std::int32_t>(a_.size()));
    if (!taper_of.empty() && taper_of[v] >= 0) {
      if (taper_edge_.empty()) taper_edge_.assign(n + static_cast<std::size_t>(inner), -1);  // shrunk below
      taper_edge_[a_.size() - 1] = static_cast<std::int32_t>(tapered_.size());
      tapered_.push_back(describe_taper(tapers[static_cast<std::size_t>(taper_of[v])], blood.alpha));
    }
  }
  vessel_edges_ = a_.size();
  if (!taper_edge_.empty()) taper_edge_.resize(vessel_edges_);
  if (vessels_.empty()) {
    if (cut) hold_cut(*cut);  // a rank with none still takes its part in every step's messages
    if (halo) hold_halo(*halo);
    return;
  }
  network_nodes_ = order.nodes.size();
  std::vector<std::int32_t>().swap(order.nodes);
  nodes_ = network_nodes_;
  if (cut) hold_cut(*cut);
  if (halo) hold_halo(*halo);
  shunt_.assign(network_nodes_, 0.0);
  shunt_pressure_.assign(network_nodes_, 0.0);
  volume_b_.assign(network_nodes_, 0.0);

  add_boundary_rows(net, laws, viscosity);

  // The inner nodes after the capacitors: no shunt.
  for (std::size_t e = 0; e < vessel_edges_; ++e)
    for (std::int32_t* k : {&a_[e], &b_[e]})
      if (*k < 0) *k = static_cast<std::int32_t>(nodes_) + ~*k;
  nodes_ += static_cast<std::size_t>(inner);
  shunt_.resize(nodes_, 0.0);
  shunt_pressure_.resize(nodes_, 0.0);
  volume_b_.resize(nodes_, 0.0);
  // The arrays grown one vessel or outlet at a time hold up to twice their size (a
  // capacitor's row appended to a per-node array doubles it; ten million vessels' edges
  // reach 1.6 times): held for the whole run, they are cut to their sizes here.
  auto fit = [](auto&... arrays) { (arrays.shrink_to_fit(), ...); };
  fit(vessels_, first_edge_, a_, b_, edge_length_, edge_root_slope_, edge_root_intercept_, tapered_,
      shunt_, shunt_pressure_, volume_b_, outlet_boundary_, rcr_outlet_boundary_, outlet_of_capacitor_, capacitor_vessel_edge_,
      capacitor_edge_sign_, edge_fixed_resistance_, inflow_node_, inflow_boundary_,
      held_node_, held_boundary_, held_reference_conductance_);
  share_shunt_pressure();

  // Each 0D vessel's volume L A(p) = L (c + d p)^2, d = 1 / beta, half at each of its nodes
  // (of each section's, L / n):
  // (L / 2) (d^2 p^2 + 2 c d p + c^2); the constant term only when asked (node_constant).
  // (Summed in double, kept in float.)
  std::vector<double> quadratic(nodes_, 0.0), linear(volume_b_.begin(), volume_b_.end());
  for (std::size_t e = 0; e < vessel_edges_; ++e) {
    const double w = edge_length_[e] / 2, c = edge_root_intercept_[e], d = edge_root_slope_[e];
    for (const std::int32_t k : {a_[e], b_[e]}) {
      const auto i = static_cast<std::size_t>(k);
      if (tapered(e)) {  // int A(p, x) dx, half at each node
        const TaperedEdge& t = tapered_[static_cast<std::size_t>(taper_edge_[e])];
        quadratic[i] += t.volume_a / 2;
        linear[i] += t.volume_b / 2;
        continue;
      }
      quadratic[i] += w * d * d;
      linear[i] += 2 * w * c * d;
    }
  }
  volume_a_.assign(quadratic.begin(), quadratic.end());
  volume_b_.assign(linear.begin(), linear.end());

  allocate_system();
}

std::int32_t LumpedVessels::edge_vessel(std::size_t e) const {
  if (e >= vessel_edges_) e = static_cast<std::size_t>(capacitor_vessel_edge_[e - vessel_edges_]);
  if (first_edge_.empty()) return vessels_[e];
  // The vessel whose sections hold e: the last whose first edge is at most e.
  const auto after = std::upper_bound(first_edge_.begin(), first_edge_.end(), static_cast<std::int32_t>(e));
  return vessels_[static_cast<std::size_t>(after - first_edge_.begin() - 1)];
}

void LumpedVessels::share_shunt_pressure() {
  if (!held_node_.empty()) return;  // a held node's changes every step
  // The same bits: no negative zero either, which would flip a zero current's sign.
  bool shared = true, found = false;
  double p = 0;
  for (std::size_t k = 0; k < shunt_.size() && shared; ++k) {
    const double q = shunt_pressure_[k];
    if (std::signbit(q)) {
      shared = false;
    } else if (shunt_[k] == 0) {
      shared = q == 0;
    } else if (!found) {
      p = q;
      found = true;
    } else {
      shared = q == p;
    }
  }
  if (!shared) return;
  uniform_shunt_pressure_ = p;
  std::vector<double>().swap(shunt_pressure_);
}

void LumpedVessels::allocate_system() {
  // In a halo the system is the link's (every rank's rows), not one of its own.
  if (!halo_.on) system_ = NodalSystem(nodes_, a_, b_);
  // The capacitors' and inner nodes' rows, and the R1 edges, are the rank's own.
  if (!share_.ghost_node.empty()) share_.ghost_node.resize(nodes_, 0);
  if (!share_.ghost_edge.empty()) share_.ghost_edge.resize(a_.size(), 0);
  if (share_.on && !share_.top) system_.open_edges(share_.root_edge);
  const std::size_t edges = a_.size();
  volume_.assign(nodes_, 0.0);
  previous_volume_ = pressure_ = previous_pressure_ = volume_;
  flow_.assign(edges, 0.0);
  previous_flow_ = flow_;
  centre_pressure_.assign(vessel_edges_, 0.0);
  resistance_ = centre_pressure_;

  if (2 * edges >= static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    throw InputError("too many 0D vessels for 32-bit indices");
  own_edge_ = true;
  for (std::size_t e = 0; e < edges && own_edge_; ++e)
    own_edge_ = static_cast<std::size_t>(std::max(a_[e], b_[e])) == e + 1;
  // Edge e at node k, unless it is k's own (not listed).
  auto listed = [&](std::size_t e, std::int32_t k) { return !own_edge_ || static_cast<std::size_t>(k) != e + 1; };
  incident_offset_.assign(nodes_ + 1, 0);
  for (std::size_t e = 0; e < edges; ++e)
    for (const std::int32_t k : {a_[e], b_[e]})
      if (listed(e, k)) ++incident_offset_[static_cast<std::size_t>(k) + 1];
  for (std::size_t k = 0; k < nodes_; ++k) incident_offset_[k + 1] += incident_offset_[k];
  incident_edge_.resize(static_cast<std::size_t>(incident_offset_.back()));
  std::vector<std::int32_t> fill(incident_offset_.begin(), incident_offset_.end() - 1);
  for (std::size_t e = 0; e < edges; ++e) {
    const auto edge = static_cast<std::int32_t>(e);
    if (listed(e, a_[e])) incident_edge_[static_cast<std::size_t>(fill[static_cast<std::size_t>(a_[e])]++)] = edge;
    if (listed(e, b_[e])) incident_edge_[static_cast<std::size_t>(fill[static_cast<std::size_t>(b_[e])]++)] = ~edge;
  }
}

void LumpedVessels::allocate_step_arrays() {
  if (rhs_.size() == nodes_) return;
  const std::size_t edges = a_.size();
  rhs_.assign(nodes_, 0.0);
  if (halo_.on) halo_.shunt.assign(nodes_, 0.0);
  conductance_.assign(edges, 0.0);
  history_.assign(edges, 0.0);
  // The R1 edges of RCR outlets keep their conductance, and have no inertance.
  for (std::size_t e = vessel_edges_; e < edges; ++e) conductance_[e] = 1 / edge_fixed_resistance_[e - vessel_edges_];
}

void LumpedVessels::release_step_arrays() {
  for (std::vector<double>* v : {&rhs_, &conductance_, &history_, &halo_.shunt}) std::vector<double>().swap(*v);
  linearised_dt_ = 0;  // the next step linearises its edges again
  system_.release_factorization();
}

void LumpedVessels::set_passes(int passes) {
  if ((share_.on || halo_.on) && passes != 1)
    throw std::invalid_argument("LumpedVessels: a run over ranks takes one linearisation a step, not " + std::to_string(passes));
  passes_ = passes;
}

void LumpedVessels::set_coupling_nodes(std::vector<std::int32_t> nodes) {
  // In a halo a coupling node is its owner's (set_halo_coupling: the run's).
  for (const std::int32_t k : nodes)
    if (is_ghost_node(static_cast<std::size_t>(k)))
      throw std::invalid_argument("LumpedVessels: coupling node " + std::to_string(k) + " is another rank's");
  coupling_nodes_ = std::move(nodes);
  held_inflow_.assign(coupling_nodes_.size(), 0.0);
  impedance_.assign(coupling_nodes_.size(), 0.0);
  dynamic_.assign(coupling_nodes_.size(), 0.0);
  coupling_scratch_.assign(coupling_nodes_.size(), 0.0);
  hold_coupling_pressures();
  std::vector<std::int32_t> slot(nodes_, -1);
  for (std::size_t j = 0; j < coupling_nodes_.size(); ++j) slot[static_cast<std::size_t>(coupling_nodes_[j])] = static_cast<std::int32_t>(j);
  coupling_edge_offset_.assign(coupling_nodes_.size() + 1, 0);
  for (std::size_t e = 0; e < vessel_edges_; ++e)
    for (const std::int32_t k : {a_[e], b_[e]})
      if (slot[static_cast<std::size_t>(k)] >= 0) ++coupling_edge_offset_[static_cast<std::size_t>(slot[static_cast<std::size_t>(k)]) + 1];
  for (std::size_t j = 0; j < coupling_nodes_.size(); ++j) coupling_edge_offset_[j + 1] += coupling_edge_offset_[j];
  coupling_edge_.resize(static_cast<std::size_t>(coupling_edge_offset_.back()));
  std::vector<std::int64_t> fill(coupling_edge_offset_.begin(), coupling_edge_offset_.end() - 1);
  for (std::size_t e = 0; e < vessel_edges_; ++e)
    for (const std::int32_t k : {a_[e], b_[e]})
      if (const auto j = slot[static_cast<std::size_t>(k)]; j >= 0)
        coupling_edge_[static_cast<std::size_t>(fill[static_cast<std::size_t>(j)]++)] = static_cast<std::int32_t>(e);
  update_dynamic_pressures();
}

void LumpedVessels::update_resistances() {
  linearised_dt_ = 0;
  parallel_blocks(static_cast<std::int64_t>(vessel_edges_), threads_, [&](std::int64_t first, std::int64_t last) {
    for (auto e = static_cast<std::size_t>(first); e < static_cast<std::size_t>(last); ++e) update_resistance(e);
  });
}

void LumpedVessels::update_resistances_and_linearise(double dt) {
  // One pass where two read each vessel's ends and law: the resistances at the new pressures,
  // then the next step's edges at the state extrapolated from them (linearise's first pass,
  // the same arithmetic), should that step be as long as this one.
  if (!tapered_.empty()) {
    parallel_blocks(static_cast<std::int64_t>(vessel_edges_), threads_, [&](std::int64_t first, std::int64_t last) {
      for (auto e = static_cast<std::size_t>(first); e < static_cast<std::size_t>(last); ++e) {
        const auto a = static_cast<std::size_t>(a_[e]), b = static_cast<std::size_t>(b_[e]);
        const double before = resistance_[e];
        update_resistance(e);
        linearise_edge(e, 2 * pressure_[a] - previous_pressure_[a], 2 * pressure_[b] - previous_pressure_[b],
                       extrapolated_resistance(resistance_[e], before), dt);
      }
    });
    linearised_dt_ = dt;
    return;
  }
  // Uniform vessels, a batch at a time, stage by stage: a vessel's arithmetic is a chain of
  // dependent operations (three table look-ups, then divisions), which the processor overlaps
  // across vessels only where their stages sit side by side in the code. Each vessel's
  // operations are those of resistance() and linearise_edge(): the same bits.
  const ViscosityTable& viscosity = *viscosity_;
  parallel_blocks(static_cast<std::int64_t>(vessel_edges_), threads_, [&](std::int64_t first, std::int64_t last) {
    constexpr std::size_t width = 8;
    double aa[width], ab[width], am[width], mu_a[width], mu_b[width], mu_m[width], extrapolated[width];
    for (auto e0 = static_cast<std::size_t>(first); e0 < static_cast<std::size_t>(last); e0 += width) {
      const std::size_t n = std::min(width, static_cast<std::size_t>(last) - e0);
      for (std::size_t i = 0; i < n; ++i) {
        const std::size_t e = e0 + i;
        const double pa = pressure_[static_cast<std::size_t>(a_[e])], pb = pressure_[static_cast<std::size_t>(b_[e])];
        const double c = edge_root_intercept_[e], d = edge_root_slope_[e];
        const double sa = c + d * pa, sb = c + d * pb, sm = c + d * 0.5 * (pa + pb);
        aa[i] = sa * sa;
        ab[i] = sb * sb;
        am[i] = sm * sm;
      }
      for (std::size_t i = 0; i < n; ++i) mu_a[i] = viscosity(aa[i]);
      for (std::size_t i = 0; i < n; ++i) mu_b[i] = viscosity(ab[i]);
      for (std::size_t i = 0; i < n; ++i) mu_m[i] = viscosity(am[i]);
      for (std::size_t i = 0; i < n; ++i) {
        const std::size_t e = e0 + i;
        const SimpsonResistance r =
            simpson_resistance(friction_k_, edge_length_[e], viscosity_factor_.empty() ? 1.0 : viscosity_factor_[e], aa[i],
                               ab[i], am[i], mu_a[i], mu_b[i], mu_m[i]);
        extrapolated[i] = extrapolated_resistance(r.resistance, resistance_[e]);
        resistance_[e] = r.resistance;
        centre_pressure_[e] = centre_pressure(e, pressure_[static_cast<std::size_t>(a_[e])],
                                              pressure_[static_cast<std::size_t>(b_[e])], r.capacity_a, r.capacity_b);
      }
      for (std::size_t i = 0; i < n; ++i) {
        const std::size_t e = e0 + i;
        const auto a = static_cast<std::size_t>(a_[e]), b = static_cast<std::size_t>(b_[e]);
        const double pa = 2 * pressure_[a] - previous_pressure_[a], pb = 2 * pressure_[b] - previous_pressure_[b];
        const double s = edge_root_intercept_[e] + edge_root_slope_[e] * 0.5 * (pa + pb);
        const EdgeLine line = bdf2_edge(extrapolated[i], density_ * edge_length_[e] / (s * s), flow_[e], previous_flow_[e], dt);
        conductance_[e] = line.conductance;
        history_[e] = line.history;
      }
    }
  });
  linearised_dt_ = dt;
}

void LumpedVessels::linearise_edge(std::size_t e, double pa, double pb, double r, double dt) {
  const double s = edge_root_intercept_[e] + edge_root_slope_[e] * 0.5 * (pa + pb);
  const double inertance = tapered(e) ? tapered_inertance(static_cast<std::int32_t>(e), pa, pb) : density_ * edge_length_[e] / (s * s);
  const EdgeLine line = bdf2_edge(r, inertance, flow_[e], previous_flow_[e], dt);
  conductance_[e] = line.conductance;
  history_[e] = line.history;
}

double LumpedVessels::resistance(std::size_t e, double pa, double pb, double& capacity_a, double& capacity_b) const {
  if (tapered(e)) {  // its interior profile is the rigid taper's (pressure_at): no capacities
    capacity_a = capacity_b = 0;
    return (viscosity_factor_.empty() ? 1.0 : viscosity_factor_[e]) * tapered_resistance(static_cast<std::int32_t>(e), pa, pb);
  }
  const double c = edge_root_intercept_[e], d = edge_root_slope_[e];
  const double sa = c + d * pa, sb = c + d * pb, sm = c + d * 0.5 * (pa + pb);
  const double aa = sa * sa, ab = sb * sb, am = sm * sm;
  const SimpsonResistance r =
      simpson_resistance(friction_k_, edge_length_[e], viscosity_factor_.empty() ? 1.0 : viscosity_factor_[e], aa, ab,
                         am, (*viscosity_)(aa), (*viscosity_)(ab), (*viscosity_)(am));
  capacity_a = r.capacity_a;
  capacity_b = r.capacity_b;
  return r.resistance;
}

void LumpedVessels::set_viscosity_factors(std::span<const double> per_vessel) {
  if (per_vessel.empty() && viscosity_factor_.empty()) return;
  for (std::size_t i = 0; i < vessels_.size(); ++i)
    set_viscosity_factor(static_cast<std::int32_t>(i), per_vessel.empty() ? 1.0 : per_vessel[static_cast<std::size_t>(vessels_[i])]);
}

void LumpedVessels::set_viscosity_factor(std::int32_t index, double factor) {
  if (viscosity_factor_.empty()) viscosity_factor_.assign(vessel_edges_, 1.0);
  const bool started = !resistance_.empty() && !previous_pressure_.empty();
  const auto i = static_cast<std::size_t>(index);
  for (std::size_t e = first_edge(i); e < first_edge(i + 1); ++e) {
    if (factor == viscosity_factor_[e]) continue;
    viscosity_factor_[e] = factor;
    if (started) refresh_resistance(e);
  }
}

void LumpedVessels::refresh_resistance(std::size_t e) {
  linearised_dt_ = 0;
  // What restore() computes from the pressures: a run resumed from a checkpoint has the same
  // resistances, whenever the factors changed.
  update_resistance(e);
}

void LumpedVessels::update_dynamic_pressures() {
  for (std::size_t j = 0; j < coupling_nodes_.size(); ++j) {
    const auto k = static_cast<std::size_t>(coupling_nodes_[j]);
    double weighted = 0, weight = 0;
    for (auto i = coupling_edge_offset_[j]; i < coupling_edge_offset_[j + 1]; ++i) {
      const auto e = static_cast<std::size_t>(coupling_edge_[static_cast<std::size_t>(i)]);
      const double s = lumen_root(e, pressure_[k], a_[e] == static_cast<std::int32_t>(k) ? 0.0 : 1.0);
      const double q = std::abs(flow_[e]), u = q / (s * s);
      weighted += q * u;
      weight += q;
    }
    const double u = weight > 0 ? weighted / weight : 0.0;
    dynamic_[j] = 0.5 * density_ * u * u;
  }
}

// ---- the tube laws of the nodes -------------------------------------------------------------

double LumpedVessels::compliance(std::int32_t node) const {
  const auto k = static_cast<std::size_t>(node);
  return node_compliance(k, pressure_[k]);
}

double LumpedVessels::pressure_from_excess(std::size_t k, double excess) const {
  // The root of a p^2 + b p - W on the branch where the compliance 2 a p + b is positive
  // (every lumen open), in the form that does not cancel.
  const double a = volume_a_[k], b = volume_b_[k];
  const double root = std::sqrt(std::max(b * b + 4 * a * excess, 0.0));
  return b > 0 ? 2 * excess / (b + root) : (root - b) / (2 * a);
}

// ---- initial states -----------------------------------------------------------------------

void LumpedVessels::start(const std::vector<double>& network_node_pressure, const std::vector<double>& vessel_flow) {
  if (empty()) return;
  for (std::size_t n = 0; n < node_of_.size(); ++n)
    if (const std::int32_t k = node_of_[n]; k >= 0) pressure_[static_cast<std::size_t>(k)] = network_node_pressure[n];
  for (std::size_t i = 0; i < vessels_.size(); ++i)
    for (std::size_t e = first_edge(i); e < first_edge(i + 1); ++e) flow_[e] = vessel_flow[static_cast<std::size_t>(vessels_[i])];
  start_inner_nodes();
  for (std::size_t j = 0; j < outlet_of_capacitor_.size(); ++j) {
    // R1 edges follow the vessels: edge vessel_edges_ + j joins the vessel's end to capacitor j.
    const std::size_t e = vessel_edges_ + j;
    const double q = capacitor_edge_sign_[j] * flow_[static_cast<std::size_t>(capacitor_vessel_edge_[j])];
    const double pc = pressure_[static_cast<std::size_t>(a_[e])] - edge_fixed_resistance_[j] * q;
    pressure_[static_cast<std::size_t>(b_[e])] = pc;
    flow_[e] = q;
  }
  for (std::size_t k = 0; k < nodes_; ++k) volume_[k] = node_excess(k, pressure_[k]);
  hold_coupling_pressures();
  update_resistances();
  restart_history();
  update_dynamic_pressures();
}

void LumpedVessels::start_from(const LumpedVessels& other) {
  if (empty() && other.empty()) return;
  if (other.nodes_ != nodes_ || other.a_ != a_ || other.b_ != b_ || other.vessels_ != vessels_)
    throw std::invalid_argument("LumpedVessels::start_from: the other 0D vessels are not built alike");
  pressure_ = other.pressure_;
  flow_ = other.flow_;
  for (std::size_t k = 0; k < nodes_; ++k) volume_[k] = node_excess(k, pressure_[k]);
  hold_coupling_pressures();
  update_resistances();
  restart_history();
  update_dynamic_pressures();
}

void LumpedVessels::start_inner_nodes() {
  // A vessel in sections: its inner nodes on the steady profile of the whole vessel between
  // its end pressures (the flow capacity G linear in p between its ends': pressure_at's).
  if (!sectioned()) return;
  for (std::size_t i = 0; i < vessels_.size(); ++i) {
    const std::size_t first = first_edge(i), last = first_edge(i + 1);
    if (last - first < 2) continue;
    const double pa = pressure_[static_cast<std::size_t>(a_[first])], pb = pressure_[static_cast<std::size_t>(b_[last - 1])];
    double ga, gb;
    resistance(first, pa, pb, ga, gb);
    for (std::size_t e = first + 1; e < last; ++e)
      pressure_[static_cast<std::size_t>(a_[e])] =
          steady_profile_pressure(pa, pb, ga, gb, static_cast<double>(e - first) / static_cast<double>(last - first));
  }
}

void LumpedVessels::start_at_rest(std::span<const TubeLaw> laws) {
  if (empty()) return;
  // Each node at the mean reference pressure of its vessels, no flow; capacitors at p_out;
  // a vessel's inner nodes at its own.
  std::vector<double> sum(nodes_, 0.0), count(nodes_, 0.0);
  for (std::size_t i = 0; i < vessels_.size(); ++i)
    for (std::size_t e = first_edge(i); e < first_edge(i + 1); ++e)
      for (const std::int32_t k : {a_[e], b_[e]}) {
        const TubeLaw& law = laws[static_cast<std::size_t>(vessels_[i])];
        // A tapered vessel rests at its measured lumen (physics/vessel_taper.hpp), at that pressure.
        sum[static_cast<std::size_t>(k)] += tapered(e) ? law.pressure(tapered_[static_cast<std::size_t>(taper_edge_[e])].taper.rest_area(0))
                                                       : law.reference_pressure;
        count[static_cast<std::size_t>(k)] += 1;
      }
  for (std::size_t k = 0; k < nodes_; ++k) pressure_[k] = is_capacitor(k) ? shunt_pressure(k) : sum[k] / count[k];
  std::fill(flow_.begin(), flow_.end(), 0.0);
  for (std::size_t k = 0; k < nodes_; ++k) volume_[k] = node_excess(k, pressure_[k]);
  hold_coupling_pressures();
  update_resistances();
  restart_history();
  update_dynamic_pressures();
}

void LumpedVessels::restart_history() {
  // BDF2 from a constant past: exact for a state at rest or steady, and the conserved
  // volume (3 V - V_prev) / 2 is V itself. The extrapolation starts constant too.
  previous_volume_ = volume_;
  previous_flow_ = flow_;
  previous_pressure_ = pressure_;
}

// ---- a step -----------------------------------------------------------------------------------

void LumpedVessels::linearise(bool extrapolated, std::span<const double> coupled_inflow) {
  const double dt = dt_;
  const auto vessels_i = static_cast<std::int64_t>(vessel_edges_), nodes_i = static_cast<std::int64_t>(nodes_);
  // The state the coefficients are taken at: the extrapolation x* = 2 x^n - x^(n-1) to t1 (an
  // error of O(dt^2) in the coefficients keeps BDF2 second order with one solve; the
  // resistance is extrapolated itself, no viscosity to evaluate, within a factor of two of
  // today's), or a Picard pass's last solution.
  auto at = [&](std::int32_t k) {
    const auto i = static_cast<std::size_t>(k);
    return extrapolated ? 2 * pressure_[i] - previous_pressure_[i] : rhs_[i];  // rhs_: the last pass's solution
  };
  // The edges of the extrapolated pass were linearised with the last step's completion
  // (complete(): update_resistances_and_linearise).
  if (!(extrapolated && linearised_dt_ == dt))
    parallel_blocks(vessels_i, threads_, [&](std::int64_t first, std::int64_t last) {
      for (auto e = static_cast<std::size_t>(first); e < static_cast<std::size_t>(last); ++e) {
        const double pa = at(a_[e]), pb = at(b_[e]);
        double r, capacity_a, capacity_b;
        if (extrapolated) {
          // The last step's resistance is a function of its pressures (no array holds it).
          const auto a = static_cast<std::size_t>(a_[e]), b = static_cast<std::size_t>(b_[e]);
          r = extrapolated_resistance(resistance_[e], resistance(e, previous_pressure_[a], previous_pressure_[b], capacity_a, capacity_b));
        } else {
          r = resistance(e, pa, pb, capacity_a, capacity_b);
        }
        linearise_edge(e, pa, pb, r, dt);
      }
    });
  linearised_dt_ = 0;
  double* const system_shunt = halo_.on ? halo_.shunt.data() : system_.shunt_workspace().data();
  // BDF2 for a node's volume, V(p) linearised at p*:
  // (3 (V* + C* (p - p*)) - 4 V^n + V^(n-1)) / (2 dt) = inflows at t1. False where the
  // compliance is not positive (a lumen closing there).
  auto node_row = [&](std::size_t k) {
    const double ps = at(static_cast<std::int32_t>(k)), c = node_compliance(k, ps);
    system_shunt[k] = 1.5 * c / dt + shunt_[k];
    double rhs =
        (1.5 * (c * ps - node_excess(k, ps)) + 0.5 * (4 * volume_[k] - previous_volume_[k])) / dt + shunt_current(k);
    for_each_incident(k, [&](std::int32_t e) {
      rhs += e >= 0 ? -history_[static_cast<std::size_t>(e)] : history_[static_cast<std::size_t>(~e)];
    });
    rhs_[k] = rhs;
    return system_shunt[k] > 0;
  };
  // On the top's rank the nodes above the shares' roots wait for their messages (their sums
  // take the root vessels' lines): every other row is made first, while the shares make theirs.
  const bool top = share_.on && share_.top;
  std::int64_t collapsed = nodes_i;
#pragma omp parallel for schedule(static) num_threads(threads_) if (threads_ > 1) reduction(min : collapsed)
  for (std::int64_t i = 0; i < nodes_i; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (is_ghost_node(k)) {  // another rank's row: a share's root (below), an open node above a share
      system_shunt[k] = 0;
      rhs_[k] = 0;
      continue;
    }
    if (top && waits_for_roots(k)) continue;
    if (!node_row(k)) collapsed = std::min<std::int64_t>(collapsed, i);
  }
  if (top) {
    take_roots();
    for (std::size_t j = 0; j < share_.root_edge.size(); ++j) {
      const auto e = static_cast<std::size_t>(share_.root_edge[j]);
      conductance_[e] = share_.root_row[LumpedLink::up_per_root * j];
      history_[e] = share_.root_row[LumpedLink::up_per_root * j + 3];
    }
    for (const std::int32_t k : share_.waiting_node)
      if (!node_row(static_cast<std::size_t>(k))) collapsed = std::min<std::int64_t>(collapsed, k);
  }
  if (collapsed < nodes_i) throw CollapsedNode{vessel_at_node(static_cast<std::size_t>(collapsed))};
  for_each_source(coupled_inflow, 1.0, [&](std::size_t k, double inflow) { rhs_[k] += inflow; });
  // On the top's rank, each share's root a leaf of its subtree's conductance and right-hand side.
  if (top)
    for (std::size_t j = 0; j < share_.root_edge.size(); ++j) {
      const std::size_t r = root_lower(static_cast<std::size_t>(share_.root_edge[j]));
      system_shunt[r] = share_.root_row[LumpedLink::up_per_root * j + 1];
      rhs_[r] = share_.root_row[LumpedLink::up_per_root * j + 2];
    }
}

void LumpedVessels::predict(double dt, std::span<const double> coupled_inflow, double inlet_flow) {
  predict(dt, coupled_inflow, inflow_node_.empty() ? std::span<const double>() : std::span<const double>(&inlet_flow, 1), {});
}

void LumpedVessels::predict(double dt, std::span<const double> coupled_inflow, std::span<const double> inflow,
                            std::span<const double> held_pressure) {
  if (halo_.on) {
    predict_on_halo(dt, coupled_inflow, inflow, held_pressure);
    return;
  }
  if (!share_.on) {
    predict_step(dt, coupled_inflow, inflow, held_pressure);
    return;
  }
  share_.potentials_down = share_.pressures_down = false;
  if (!share_.top) {
    std::exception_ptr failure;
    try {
      predict_step(dt, coupled_inflow, inflow, held_pressure);
    } catch (...) {
      failure = in_words(std::current_exception());
    }
    send_roots(failure);
    return;
  }
  // The top's rank: its rows first, the shares' roots taken in its linearisation.
  share_.awaiting_roots = true;
  try {
    predict_step(dt, coupled_inflow, inflow, held_pressure);
    if (share_.awaiting_roots) take_roots();  // none of its own to make first
  } catch (...) {
    abandon_step(in_words(std::current_exception()));
  }
}

void LumpedVessels::predict_step(double dt, std::span<const double> coupled_inflow, std::span<const double> inflow,
                                 std::span<const double> held_pressure) {
  if (empty()) return;
  if (inflow.size() != inflow_node_.size() || held_pressure.size() != held_node_.size())
    throw std::invalid_argument("LumpedVessels::predict: one value per boundary flow and pressure");
  dt_ = dt;
  allocate_step_arrays();
  inflow_.assign(inflow.begin(), inflow.end());
  // A held node's shunt in the solve (boundaries/pressure_end.hpp), sized by what else
  // reaches it: its vessel's conductance at rest and its compliance's C / dt. complete() then
  // puts the node at the held pressure exactly.
  for (std::size_t j = 0; j < held_node_.size(); ++j) {
    const auto k = static_cast<std::size_t>(held_node_[j]);
    const LumpedShunt held = PressureEnd{held_pressure[j]}.held_shunt(
        held_reference_conductance_[j] + 1.5 * node_compliance(k, pressure_[k]) / dt);
    shunt_[k] = held.conductance;
    shunt_pressure_[k] = held.pressure;
  }
  for (int pass = 0; pass < passes_; ++pass) {
    // Each further (Picard) pass takes the coefficients again at the last solution.
    linearise(pass == 0, coupled_inflow);
    if (halo_.on) return;  // solved over every rank's rows (predict_on_halo)
    // The forward half of the solve goes with the factorisation; complete() adds the 1D
    // ends' departures from the held inflows to it and takes the backward half.
    if (system_.factorize_forward_in_place(conductance_, rhs_) >= 0)
      throw InputError("the 0D vessels have a part with no path to an outlet");
    if (pass + 1 < passes_) system_.backward(rhs_, rhs_);
  }
  if (coupling_nodes_.empty()) return;
  std::copy(coupled_inflow.begin(), coupled_inflow.end(), held_inflow_.begin());
  // The predicted pressures where the 1D ends read them, and Z_i = (K^-1)_ii there: both
  // along the coupling nodes' paths to their roots only (selected inversion on a tree).
  predict_coupling_pressures();
  system_.inverse_diagonal(coupling_nodes_, impedance_);
}

void LumpedVessels::predict_again(std::span<const double> coupled_inflow) {
  if (halo_.on) {  // collective: every rank, own coupling nodes or none
    add_halo_departures([&](std::size_t s) { return coupled_inflow[s] - held_inflow_[s]; });
    std::copy(coupled_inflow.begin(), coupled_inflow.end(), held_inflow_.begin());
    for (std::size_t j = 0; j < coupling_nodes_.size(); ++j) coupling_predicted_[j] = rhs_[static_cast<std::size_t>(coupling_nodes_[j])];
    return;
  }
  if (coupling_nodes_.empty()) return;
  for (std::size_t j = 0; j < coupling_nodes_.size(); ++j) coupling_scratch_[j] = coupled_inflow[j] - held_inflow_[j];
  system_.add_forward(coupling_nodes_, coupling_scratch_, rhs_);
  std::copy(coupled_inflow.begin(), coupled_inflow.end(), held_inflow_.begin());
  predict_coupling_pressures();
}

void LumpedVessels::predict_coupling_pressures() {
  system_.backward_at(coupling_nodes_, rhs_, coupling_predicted_);
}

void LumpedVessels::hold_coupling_pressures() {
  coupling_predicted_.resize(coupling_nodes_.size());
  for (std::size_t j = 0; j < coupling_nodes_.size(); ++j)
    coupling_predicted_[j] = pressure_.empty() ? 0.0 : pressure_[static_cast<std::size_t>(coupling_nodes_[j])];
}

void LumpedVessels::complete(std::span<const double> coupled_volume, std::span<double> boundary_volume) {
  if (!share_.on) {
    complete_step(coupled_volume, boundary_volume);
    return;
  }
  // The messages down are sent and taken within the step (complete_step); a failure before
  // both went down is every rank's.
  try {
    if (!share_.top) take_potentials();
    complete_step(coupled_volume, boundary_volume);
    if (!share_.potentials_down) answer_potentials();  // a top with no 0D vessel of its own
    if (!share_.pressures_down) share_.top ? answer_pressures() : take_pressures();
  } catch (...) {
    abandon_step(in_words(std::current_exception()));
  }
}

void LumpedVessels::complete_step(std::span<const double> coupled_volume, std::span<double> boundary_volume) {
  const double dt = dt_;
  if (halo_.on)  // collective: the departures, then (below) the ghosts
    add_halo_departures([&](std::size_t s) { return coupled_volume[s] / dt - held_inflow_[s]; });
  if (empty()) {
    if (halo_.on) halo_.link.fill_ghosts({});
    return;
  }
  // The departure of the 1D ends' mean inflows from those held, into the forward half.
  if (!coupling_nodes_.empty() && !halo_.on) {
    for (std::size_t j = 0; j < coupling_nodes_.size(); ++j) coupling_scratch_[j] = coupled_volume[j] / dt - held_inflow_[j];
    system_.add_forward(coupling_nodes_, coupling_scratch_, rhs_);
  }
  if (!halo_.on) system_.backward(rhs_, rhs_);  // a halo's rhs_ holds the pressures already
  if (share_.on && share_.top) answer_potentials();  // the shares' backward halves go on meanwhile
  const std::vector<double>& p1 = rhs_;  // now the pressures at t1
  for (std::size_t j = 0; j < coupling_nodes_.size(); ++j) coupling_predicted_[j] = p1[static_cast<std::size_t>(coupling_nodes_[j])];
  const auto edges = static_cast<std::int64_t>(a_.size());
  const auto blocks = static_cast<std::int64_t>((nodes_ + block - 1) / block);
#pragma omp parallel num_threads(threads_) if (threads_ > 1)
  {
#pragma omp for schedule(static)
    for (std::int64_t i = 0; i < edges; ++i) {
      const auto e = static_cast<std::size_t>(i);
      previous_flow_[e] = conductance_[e] * (p1[static_cast<std::size_t>(a_[e])] - p1[static_cast<std::size_t>(b_[e])]) + history_[e];
    }
    // Each node's net inflow at t1 (BDF2 takes the right-hand side there), as the solve had
    // it, and from it the volume: exactly what came in, (3 V - 4 V^n + V^(n-1)) / 2 =
    // dt inflow (+ the 1D ends' and the inlet's volumes, below); the pressure from the tube
    // laws. The new values go where the oldest were (the histories swap after), so a
    // node's row is read and written once.
#pragma omp for schedule(static)
    for (std::int64_t b = 0; b < blocks; ++b) {
      const std::size_t first = static_cast<std::size_t>(b) * block, last = std::min(first + block, nodes_);
      for (std::size_t k = first; k < last; ++k) {
        if (is_ghost_node(k)) {  // its rank's to complete (a share's nodes above it: below)
          previous_volume_[k] = volume_[k];
          previous_pressure_[k] = pressure_[k];
          continue;
        }
        const double shunted = shunt_[k] * p1[k] - shunt_current(k);
        double inflow = -shunted;
        for_each_incident(k, [&](std::int32_t e) {
          inflow += e >= 0 ? -previous_flow_[static_cast<std::size_t>(e)] : previous_flow_[static_cast<std::size_t>(~e)];
        });
        if (!held_.empty() && held_[k]) {
          // Dirichlet: the node sits at the held pressure, and the boundary lets in what its
          // volume and its vessel take (the stiff shunt's own flow, G (p - p_held), is
          // round-off times G: not taken).
          const double next_volume = node_excess(k, shunt_pressure(k));
          const auto j = static_cast<std::size_t>(held_[k] - 1);
          held_out_[j] = inflow + shunted - (3 * next_volume - 4 * volume_[k] + previous_volume_[k]) / (2 * dt);
          previous_volume_[k] = next_volume;
          previous_pressure_[k] = shunt_pressure(k);
          continue;
        }
        const double next = (4 * volume_[k] - previous_volume_[k] + 2 * dt * inflow) / 3;
        previous_volume_[k] = next;
        previous_pressure_[k] = pressure_from_excess(k, next);
      }
    }
  }
  volume_.swap(previous_volume_);
  pressure_.swap(previous_pressure_);
  for_each_source(coupled_volume, dt, [&](std::size_t k, double volume) {
    volume_[k] += 2 * volume / 3;
    pressure_[k] = pressure_from_excess(k, volume_[k]);
  });
  previous_flow_.swap(flow_);  // the new flows went where the oldest were
  if (share_.on) share_.top ? answer_pressures() : take_pressures();
  if (share_.on && !share_.top)  // the top's nodes above the roots: their pressures as the top completed them
    for (std::size_t j = 0; j < share_.root_edge.size(); ++j) {
      const std::size_t u = root_upper(static_cast<std::size_t>(share_.root_edge[j]));
      pressure_[u] = share_.root_row[j];
      volume_[u] = node_excess(u, pressure_[u]);
    }
  if (halo_.on) {  // the ghosts' pressures as their owners completed them
    halo_.link.fill_ghosts(pressure_);
    for (std::size_t k = 0; k < nodes_; ++k)
      if (is_ghost_node(k)) volume_[k] = node_excess(k, pressure_[k]);
  }
  for (std::size_t e = 0; e < passed_.size(); ++e) passed_[e] += dt * flow_[e];
  update_resistances_and_linearise(dt);
  update_dynamic_pressures();
  // Across the network's boundary, each boundary's volume: flows, outlet shunts and the R1
  // of RCR outlets, held pressures' shunts.
  if (boundary_volume.empty()) return;
  for (std::size_t j = 0; j < inflow_node_.size(); ++j)
    boundary_volume[static_cast<std::size_t>(inflow_boundary_[j])] += dt * inflow_[j];
  for (std::size_t j = 0; j < held_node_.size(); ++j)
    boundary_volume[static_cast<std::size_t>(held_boundary_[j])] -= dt * held_outflow(j);
  // Each outlet its own boundary: in parallel (a tree's two million, every step).
  parallel_blocks(static_cast<std::int64_t>(outlet_boundary_.size()), threads_, [&](std::int64_t first, std::int64_t last) {
    for (auto j = static_cast<std::size_t>(first); j < static_cast<std::size_t>(last); ++j) {
      const OutletNode& o = outlet_boundary_[j];
      const auto k = static_cast<std::size_t>(o.node);
      boundary_volume[static_cast<std::size_t>(o.boundary)] -= dt * (shunt_[k] * p1[k] - shunt_current(k));
    }
  });
  for (const OutletEdge& o : rcr_outlet_boundary_)
    boundary_volume[static_cast<std::size_t>(o.boundary)] -= dt * flow_[static_cast<std::size_t>(o.r1_edge)];
}

// ---- what the rest of the solver reads -------------------------------------------------------

double LumpedVessels::edge_pressure_at(std::size_t e, double x) const {
  const double pa = pressure_[static_cast<std::size_t>(a_[e])], pb = pressure_[static_cast<std::size_t>(b_[e])];
  const double drop = pa - pb;
  if (drop == 0 || x <= 0) return pa;
  if (x >= 1) return pb;
  if (tapered(e)) return pa - drop * resistance_fraction(e, x);  // the rigid taper's profile
  if (x == 0.5) return centre_pressure_[e];
  // The flow capacities at the ends, as the last update of the resistances had them (the
  // same arithmetic on the same pressures: the same bits).
  double ga, gb;
  resistance(e, pa, pb, ga, gb);
  return steady_profile_pressure(pa, pb, ga, gb, x);
}

double LumpedVessels::centre_pressure(std::size_t e, double pa, double pb, double ga, double gb) const {
  const double drop = pa - pb;
  if (drop == 0) return pa;
  if (tapered(e)) return pa - drop * resistance_fraction(e, 0.5);
  return steady_profile_pressure(pa, pb, ga, gb, 0.5);
}

void LumpedVessels::update_resistance(std::size_t e) {
  const double pa = pressure_[static_cast<std::size_t>(a_[e])], pb = pressure_[static_cast<std::size_t>(b_[e])];
  double ga, gb;
  resistance_[e] = resistance(e, pa, pb, ga, gb);
  centre_pressure_[e] = centre_pressure(e, pa, pb, ga, gb);
}

std::int32_t LumpedVessels::vessel_at_node(std::size_t k) const {
  std::int32_t first = 0;
  bool any = false;
  for_each_incident(k, [&](std::int32_t incident) {
    if (!any) first = incident;
    any = true;
  });
  if (any) {
    const auto e = static_cast<std::size_t>(first >= 0 ? first : ~first);
    const std::size_t vessel_edge = e < vessel_edges_ ? e : static_cast<std::size_t>(capacitor_vessel_edge_[e - vessel_edges_]);
    const std::size_t slot = first_edge_.empty() ? vessel_edge
                                                 : static_cast<std::size_t>(std::upper_bound(first_edge_.begin(), first_edge_.end(),
                                                                                             static_cast<std::int32_t>(vessel_edge)) -
                                                                            first_edge_.begin() - 1);
    return vessels_[slot];
  }
  return vessels_.front();
}

double LumpedVessels::node_constant(std::size_t k) const {
  // Half of each adjacent section's L c^2 (a tapered vessel's int c^2 dx), in the order of
  // its edges, as the constructor summed a and b.
  double constant = 0;
  for_each_incident(k, [&](std::int32_t incident) {
    const auto e = static_cast<std::size_t>(incident >= 0 ? incident : ~incident);
    if (e >= vessel_edges_) return;  // an R1 edge
    if (tapered(e)) {
      constant += tapered_[static_cast<std::size_t>(taper_edge_[e])].volume_c / 2;
      return;
    }
    const double w = edge_length_[e] / 2, c = edge_root_intercept_[e];
    constant += w * c * c;
  });
  return constant;
}

std::size_t LumpedVessels::section_at(std::size_t i, double x, double& within) const {
  const std::size_t first = first_edge(i), n = first_edge(i + 1) - first;
  if (n == 1) {
    within = x;
    return first;
  }
  const double scaled = std::clamp(x, 0.0, 1.0) * static_cast<double>(n);
  const std::size_t s = std::min(static_cast<std::size_t>(scaled), n - 1);
  within = scaled - static_cast<double>(s);
  return first + s;
}

double LumpedVessels::pressure_at(std::int32_t index, double x) const {
  double within;
  const std::size_t e = section_at(static_cast<std::size_t>(index), x, within);
  return edge_pressure_at(e, within);
}

double LumpedVessels::flow(std::int32_t index) const {
  const auto i = static_cast<std::size_t>(index);
  const std::size_t first = first_edge(i), last = first_edge(i + 1);
  if (last - first == 1) return flow_[first];
  double sum = 0;
  for (std::size_t e = first; e < last; ++e) sum += flow_[e];
  return sum / static_cast<double>(last - first);
}

double LumpedVessels::flow_at(std::int32_t index, double x) const {
  double within;
  const auto i = static_cast<std::size_t>(index);
  const std::size_t e = section_at(i, x, within);
  // At a node between two sections, the flow is theirs in the mean (the node's compliance takes the difference).
  if (within == 0 && e > first_edge(i)) return 0.5 * (flow_[e - 1] + flow_[e]);
  return flow_[e];
}

double LumpedVessels::sectioned_volume(std::int32_t index) const {
  const auto i = static_cast<std::size_t>(index);
  double v = 0;
  for (std::size_t e = first_edge(i); e < first_edge(i + 1); ++e) {
    const double sa = lumen_root(e, pressure_[static_cast<std::size_t>(a_[e])]), sb = lumen_root(e, pressure_[static_cast<std::size_t>(b_[e])]);
    v += edge_length_[e] * 0.5 * (sa * sa + sb * sb);
  }
  return v;
}

void LumpedVessels::sample(double x, std::span<double> area, std::span<double> flow, std::span<double> pressure,
                           int threads) const {
  const auto vessels = static_cast<std::int64_t>(vessels_.size());
#pragma omp parallel for schedule(static) num_threads(threads) if (threads > 1)
  for (std::int64_t i = 0; i < vessels; ++i) {
    const auto v = static_cast<std::size_t>(vessels_[static_cast<std::size_t>(i)]);
    double within;
    const std::size_t e = section_at(static_cast<std::size_t>(i), x, within);
    const double p = edge_pressure_at(e, within);
    const double s = lumen_root(e, p, within);
    area[v] = s * s;
    flow[v] = sectioned() ? flow_at(static_cast<std::int32_t>(i), x) : flow_[e];
    if (!pressure.empty()) pressure[v] = p;
  }
}

void LumpedVessels::centre_batch(std::size_t first, std::size_t n, CentreBatch& batch) const {
  batch.n = n;
  batch.first = first;
  if (sectioned()) {
    for (std::size_t i = 0; i < n; ++i) {
      const auto index = static_cast<std::int32_t>(first + i);
      double within;
      const std::size_t e = section_at(first + i, 0.5, within);
      batch.pressure[i] = edge_pressure_at(e, within);
      const double root = lumen_root(e, batch.pressure[i], within);
      batch.area[i] = root * root;
      batch.flow[i] = flow_at(index, 0.5);
      batch.vessel[i] = static_cast<std::size_t>(vessels_[first + i]);
    }
    return;
  }
  for (std::size_t i = 0; i < n; ++i) batch.pressure[i] = edge_pressure_at(first + i, 0.5);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t e = first + i;
    const double root = lumen_root(e, batch.pressure[i], 0.5);
    batch.area[i] = root * root;
    batch.flow[i] = flow_[e];
    batch.vessel[i] = static_cast<std::size_t>(vessels_[e]);
  }
}

double LumpedVessels::stored_volume() const {
  // Summed in the network's order: the same bits whatever the arrays' order.
  double v = 0;
  for (const std::int32_t node : network_order_nodes())
    if (const auto k = static_cast<std::size_t>(node); !is_capacitor(k)) v += stored_volume(node);
  return v;
}

double LumpedVessels::capacitor_pressure(std::size_t outlet) const {
  if (empty() || capacitor_of_outlet_[outlet] < 0) return std::numeric_limits<double>::quiet_NaN();
  return pressure_[network_nodes_ + static_cast<std::size_t>(capacitor_of_outlet_[outlet])];
}

void LumpedVessels::shift_pressures(std::span<const double> network_node_dp, std::span<const double> outlet_dp) {
  if (empty()) return;
  // Each node's shift goes in volume_ first (the volumes are made again from the pressures below).
  std::vector<double>& dp = volume_;
  for (std::size_t n = 0; n < node_of_.size(); ++n)
    if (const std::int32_t k = node_of_[n]; k >= 0) dp[static_cast<std::size_t>(k)] = network_node_dp[n];
  for (std::size_t j = 0; j < outlet_of_capacitor_.size(); ++j)
    dp[network_nodes_ + j] = outlet_dp[static_cast<std::size_t>(outlet_of_capacitor_[j])];
  for (std::size_t k = 0; k < network_nodes_ + outlet_of_capacitor_.size(); ++k) pressure_[k] += dp[k];
  // Inner nodes by their place between their vessel's ends.
  for (std::size_t i = 0; sectioned() && i < vessels_.size(); ++i) {
    const std::size_t first = first_edge(i), n = first_edge(i + 1) - first;
    const double da = dp[static_cast<std::size_t>(a_[first])], db = dp[static_cast<std::size_t>(b_[first + n - 1])];
    for (std::size_t s = 1; s < n; ++s)
      pressure_[static_cast<std::size_t>(a_[first + s])] += da + (db - da) * static_cast<double>(s) / static_cast<double>(n);
  }
  for (std::size_t k = 0; k < nodes_; ++k) volume_[k] = node_excess(k, pressure_[k]);
  hold_coupling_pressures();
  update_resistances();
  restart_history();
  update_dynamic_pressures();
}

void LumpedVessels::check(double time, std::span<const std::int64_t> vessel_id) const {
  for (const std::int32_t index : index_of_vessel_) {  // the first in the network's order is named
    if (index < 0) continue;
    const auto i = static_cast<std::size_t>(index);
    for (std::size_t e = first_edge(i); e < first_edge(i + 1); ++e) {
      const double s_a = lumen_root(e, pressure_[static_cast<std::size_t>(a_[e])], 0.0);
      const double s_b = lumen_root(e, pressure_[static_cast<std::size_t>(b_[e])], 1.0);
      if (!(s_a > 0) || !(s_b > 0) || !std::isfinite(flow_[e]) || !std::isfinite(s_a * s_b))
        throw SolutionBreakdown(vessel_id[static_cast<std::size_t>(vessels_[i])], time);
    }
  }
}

}  // namespace hemotree
