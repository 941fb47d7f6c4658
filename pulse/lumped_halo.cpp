#include "pulse/lumped_halo.hpp"

#include <algorithm>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>

#include "pulse/lumped_vessels.hpp"
#include "pulse/network_boundaries.hpp"

namespace hemotree {

std::vector<std::int32_t> lumped_node_ranks(const Network& net, const LumpedOrder& whole,
                                            std::span<const std::int32_t> vessel_rank) {
  std::vector<std::int32_t> owner(net.node_count(), -1);
  for (const std::int32_t v : whole.vessels)
    for (const std::int32_t node : {net.from[static_cast<std::size_t>(v)], net.to[static_cast<std::size_t>(v)]})
      if (owner[static_cast<std::size_t>(node)] < 0) owner[static_cast<std::size_t>(node)] = vessel_rank[static_cast<std::size_t>(v)];
  return owner;
}

std::size_t hold_at_an_own_node(const Network& net, const LumpedOrder& whole, std::span<std::int32_t> vessel_rank,
                                int ranks) {
  const std::vector<std::int32_t> owner = lumped_node_ranks(net, whole, vessel_rank);
  std::vector<std::size_t> vessels(static_cast<std::size_t>(ranks), 0);
  for (const std::int32_t r : vessel_rank) ++vessels[static_cast<std::size_t>(r)];
  std::size_t moved = 0;
  for (const std::int32_t v : whole.vessels) {
    std::int32_t& r = vessel_rank[static_cast<std::size_t>(v)];
    const std::int32_t from = owner[static_cast<std::size_t>(net.from[static_cast<std::size_t>(v)])],
                       to = owner[static_cast<std::size_t>(net.to[static_cast<std::size_t>(v)])];
    if (r == from || r == to || vessels[static_cast<std::size_t>(r)] == 1) continue;
    --vessels[static_cast<std::size_t>(r)];
    ++vessels[static_cast<std::size_t>(from)];
    r = from;
    ++moved;
  }
  return moved;
}

LumpedHalo lumped_halo(const Network& net, const LumpedOrder& whole, std::span<const std::int32_t> vessel_rank,
                       int ranks, int rank) {
  for (const std::int32_t v : whole.vessels)
    if (const std::int32_t r = vessel_rank[static_cast<std::size_t>(v)]; r < 0 || r >= ranks)
      throw std::invalid_argument("lumped_halo: vessel " + std::to_string(net.id[static_cast<std::size_t>(v)]) + " on rank " +
                                  std::to_string(r) + " of " + std::to_string(ranks));
  LumpedHalo halo;
  halo.rank = rank;
  const std::vector<std::int32_t> owner = lumped_node_ranks(net, whole, vessel_rank);
  std::vector<bool> keep(net.vessel_count(), false);
  for (const std::int32_t v : whole.vessels) {
    const auto i = static_cast<std::size_t>(v);
    const bool own = vessel_rank[i] == rank;
    const bool at_own_node = owner[static_cast<std::size_t>(net.from[i])] == rank || owner[static_cast<std::size_t>(net.to[i])] == rank;
    if (!own && !at_own_node) continue;
    keep[i] = true;
    if (!own) halo.halo_vessels.push_back(v);
  }
  halo.order = restrict_order(whole, net, keep);
  for (const std::int32_t node : halo.order.nodes)
    if (owner[static_cast<std::size_t>(node)] != rank) halo.ghost_nodes.push_back(node);
  halo.key_rank = owner;
  // An outlet's capacitor node where LumpedVessels makes one (an RCR with a capacitance at a
  // 0D node: lumped_places' rule), its node's owner's; no node, no row, elsewhere.
  const RunBoundaries boundaries(net);
  for (std::size_t i = 0; i < boundaries.size(); ++i) {
    if (!boundaries.is_outlet(i)) continue;
    const Outlet& o = boundaries.outlet(i);
    const std::int32_t at = owner[static_cast<std::size_t>(boundaries.node(i))];
    halo.key_rank.push_back(at >= 0 && o.type == BoundaryType::rcr && o.c > 0 ? at : -1);
  }
  return halo;
}

// ---- LumpedVessels' part in a halo -----------------------------------------------------------

void LumpedVessels::hold_halo(const LumpedHalo& halo) {
  if (sectioned()) throw std::invalid_argument("LumpedVessels: a halo takes one pi section a 0D vessel");
  halo_.on = true;
  halo_.key_rank = halo.key_rank;
  share_.ghost_node.assign(network_nodes_, 0);
  for (const std::int32_t node : halo.ghost_nodes) share_.ghost_node[static_cast<std::size_t>(node_of_[static_cast<std::size_t>(node)])] = 1;
  share_.ghost_edge.assign(a_.size(), 0);
  for (const std::int32_t v : halo.halo_vessels)
    share_.ghost_edge[first_edge(static_cast<std::size_t>(index_of_vessel_[static_cast<std::size_t>(v)]))] = 1;
}

LumpedHaloSystem LumpedVessels::halo_system() const {
  LumpedHaloSystem s;
  s.node_key.assign(nodes_, -1);
  for (std::size_t n = 0; n < node_of_.size(); ++n)
    if (node_of_[n] >= 0) s.node_key[static_cast<std::size_t>(node_of_[n])] = static_cast<std::int64_t>(n);
  for (std::size_t j = 0; j < outlet_of_capacitor_.size(); ++j)
    s.node_key[network_nodes_ + j] = static_cast<std::int64_t>(node_of_.size()) + outlet_of_capacitor_[j];
  s.key_rank = halo_.key_rank;
  s.a = a_;
  s.b = b_;
  return s;
}

void LumpedVessels::predict_on_halo(double dt, std::span<const double> coupled_inflow, std::span<const double> inflow,
                                    std::span<const double> held_pressure) {
  // Every rank's rows first; a lumen closing on any rank ends the step on every rank (the
  // least vessel's) before the solve, which every rank must enter.
  constexpr std::int64_t none = std::numeric_limits<std::int64_t>::max();
  std::int64_t collapsed = none;
  try {
    predict_step(dt, coupled_inflow, inflow, held_pressure);
  } catch (const CollapsedNode& c) {
    collapsed = c.vessel;
  }
  if (const std::int64_t least = halo_.link.least(collapsed); least != none) throw CollapsedNode{static_cast<std::int32_t>(least)};
  halo_.link.solve(conductance_, halo_.shunt, rhs_, rhs_);  // rhs_: the pressures at t1, ghosts too
  if (halo_.coupled_node.empty()) return;
  // Each coupling node's response z_j = K^-1 e_j (the same system: the one-process run's
  // selected inversion and partial solves are of a factorisation no rank holds here): its
  // impedance at its owner, and what its 1D ends' departures from the held inflows move
  // (predict_again, complete).
  const std::size_t couplings = halo_.coupled_node.size();
  halo_.response.resize(couplings * nodes_);
  std::vector<double> unit(nodes_, 0.0);
  for (std::size_t j = 0; j < couplings; ++j) {
    const std::int32_t k = halo_.coupled_node[j];
    if (k >= 0 && !is_ghost_node(static_cast<std::size_t>(k))) unit[static_cast<std::size_t>(k)] = 1;
    halo_.link.solve_again(unit, std::span<double>(halo_.response).subspan(j * nodes_, nodes_));
    if (k >= 0) unit[static_cast<std::size_t>(k)] = 0;
    if (const std::int32_t slot = halo_.coupled_slot[j]; slot >= 0)
      impedance_[static_cast<std::size_t>(slot)] = halo_.response[j * nodes_ + static_cast<std::size_t>(k)];
  }
  std::copy(coupled_inflow.begin(), coupled_inflow.end(), held_inflow_.begin());
  for (std::size_t j = 0; j < coupling_nodes_.size(); ++j) coupling_predicted_[j] = rhs_[static_cast<std::size_t>(coupling_nodes_[j])];
}

void LumpedVessels::set_halo_coupling(std::span<const std::int64_t> network_nodes) {
  if (!halo_.on) throw std::logic_error("LumpedVessels::set_halo_coupling without a halo");
  halo_.coupled_node.clear();
  halo_.coupled_slot.clear();
  for (const std::int64_t node : network_nodes) {
    const std::int32_t k = node_of_.empty() ? -1 : node_of_[static_cast<std::size_t>(node)];
    halo_.coupled_node.push_back(k);
    const auto at = std::find(coupling_nodes_.begin(), coupling_nodes_.end(), k);
    halo_.coupled_slot.push_back(k >= 0 && at != coupling_nodes_.end() ? static_cast<std::int32_t>(at - coupling_nodes_.begin()) : -1);
  }
  halo_.departure.assign(network_nodes.size(), 0.0);
}

void LumpedVessels::add_halo_departures(const std::function<double(std::size_t slot)>& departure) {
  const std::size_t couplings = halo_.coupled_node.size();
  if (couplings == 0) return;
  for (std::size_t j = 0; j < couplings; ++j)
    halo_.departure[j] = halo_.coupled_slot[j] >= 0 ? departure(static_cast<std::size_t>(halo_.coupled_slot[j])) : 0.0;
  halo_.link.sum(halo_.departure);  // each its owner's alone: every rank the same bits
  for (std::size_t j = 0; j < couplings; ++j) {
    const double d = halo_.departure[j];
    const double* z = halo_.response.data() + j * nodes_;
    for (std::size_t k = 0; k < nodes_; ++k) rhs_[k] += d * z[k];
  }
}

}  // namespace hemotree
