// What one rank holds of a run's 0D vessels when the run is spread over ranks, and the
// messages of a step between the ranks (docs/scaling.md, "The pulsatile run over ranks").
//
// The 0D vessels form a forest (a tree's: the run over ranks is on trees); the partition gives
// each rank whole subtrees, and one rank, the top's, also the vessels above them. Each rank
// eliminates its subtrees up to their roots in its step's forward half and sends, per root
// vessel (u, r) (u held by the top's rank), what the top needs of it: the vessel's BDF2 line
// Q = g (x_u - x_r) + h, and what its subtree leaves at r, the conductance to ground S_r and
// the forward right-hand side y_r (network_flow/nodal_system.hpp, open roots). The top's rank
// holds these vessels as ghosts: their lines in u's sums, r as a leaf of shunt S_r. It solves
// (with the 1D vessels, all of which it holds, between the halves) and answers each root
// vessel with x_r, x_u and u's pressure after the step, from which the share finishes its
// subtree. Every node's sums run over the same terms in the same order as the whole run's,
// so every rank's numbers are the one-process run's bits.
#pragma once

#include <cstdint>
#include <exception>
#include <functional>
#include <span>
#include <vector>

#include "formats/network.hpp"
#include "pulse/lumped_order.hpp"

namespace hemotree {

struct LumpedCut {
  int rank = 0, top_rank = 0;
  // Its own vessels and, on the top's rank, the other ranks' root vessels, with their nodes:
  // each in the whole run's order.
  LumpedOrder order;
  // On the top's rank: every other rank's root vessels in the messages' order (rank after
  // rank, each rank's in the whole order). Elsewhere: its own root vessels, in that order.
  std::vector<std::int32_t> root_vessels;
  // The network nodes it holds for its vessels' ends alone, whose rows another rank holds
  // (no boundary there, no volume of its own): the top's rank the shares' roots r, a share
  // the top's nodes u above its roots.
  std::vector<std::int32_t> ghost_nodes;
  // Per rank, its root vessels (the messages' sizes; none on the top's rank).
  std::vector<int> roots;
  bool top() const { return rank == top_rank; }
};

// The cut of the whole run's 0D vessels (`whole`, pulse/lumped_order: every node hangs from one
// before it) by `vessel_rank` (per network vessel its rank in [0, ranks); a 1D vessel's is
// not read), for `rank`. std::invalid_argument where a rank's vessel hangs from another rank's
// that is not the top's (the ranks must hold whole subtrees under the top's), or a vessel is
// more than one pi section (`sections`, as LumpedVessels takes them; empty: all one).
LumpedCut lumped_cut(const Network& net, const LumpedOrder& whole, std::span<const std::int32_t> vessel_rank,
                     int ranks, int top_rank, int rank, std::span<const std::uint8_t> sections = {});

// A step's two messages, carried by the caller (MPI, or threads playing ranks in a test).
struct LumpedLink {
  // The numbers for the top's rank: this rank's (or, where its move failed, `failure`);
  // returns on the top's rank every other rank's, rank after rank, or sets `failed` where some
  // rank failed (the top then goes straight to `down`); elsewhere nothing.
  std::function<std::vector<double>(std::span<const double> numbers, std::exception_ptr failure, bool& failed)> up;
  // The top's answers, rank after rank, per_root numbers a root (or, on any rank, its
  // failure), out; returns this rank's. Where any rank failed, throws its refusal on every
  // rank alike.
  std::function<std::vector<double>(std::span<const double> answers, std::exception_ptr failure, std::size_t per_root)> down;
  static constexpr std::size_t up_per_root = 4;  // g, S_r, y_r, h
  // Down twice a step: the potentials at the root vessel's ends (x_r, x_u) as soon as the
  // top's backward half has them, then u's pressure after the step once the top has
  // completed its nodes: a share completes its own in the meantime.
  static constexpr std::size_t potentials_per_root = 2, pressures_per_root = 1;
};

}  // namespace hemotree
