// What one rank holds of a 0D system spread over ranks where it has loops (no top to gather
// to: docs/scaling.md, "A 0D system with loops over ranks").
//
// The partition gives each 0D vessel a rank, and each node of the 0D vessels the rank of its
// first vessel in the whole run's order: the node's owner, which holds its row of the step's
// system (its volume, its boundary, its sums). A rank holds its own vessels and, as a halo,
// every other rank's vessel that ends at one of its nodes: it linearises them alike from the
// same state (their BDF2 lines, the same bits as their own rank's), so that each of its rows
// sums all of its node's vessels in the whole run's order. The far ends of its vessels and
// halo that another rank owns are its ghost nodes: it holds their pressures for its vessels'
// lines, as their owner sends them after each step. The system is then one linear system
// over every rank's rows, solved by the caller's distributed solver (PETSc): each node's
// pressure at the step's end the same on every rank that holds it, whence every vessel's flow
// alike on its own rank and in a halo.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "formats/network.hpp"
#include "pulse/lumped_order.hpp"

namespace hemotree {

struct LumpedHalo {
  int rank = 0;
  // Its own vessels and halo and their nodes, in the whole run's order.
  LumpedOrder order;
  std::vector<std::int32_t> halo_vessels;  // other ranks' vessels at its nodes
  std::vector<std::int32_t> ghost_nodes;   // the nodes of its vessels and halo it does not own
  // Per network node its owner (-1: no 0D vessel's), then per run outlet (RunBoundaries'
  // outlet order) its capacitor's: its node's owner (-1: no capacitor). What a distributed
  // solver numbers every rank's rows by.
  std::vector<std::int32_t> key_rank;
};

// The owner of every node of the 0D vessels (-1 elsewhere): the rank of its first vessel in
// `whole` (a node at the end of one vessel, a boundary's, is that vessel's rank's).
std::vector<std::int32_t> lumped_node_ranks(const Network& net, const LumpedOrder& whole,
                                            std::span<const std::int32_t> vessel_rank);

// Each 0D vessel whose rank owns neither of its nodes (both nodes' first vessels another
// rank's) moved to its `from` node's owner: being the first vessel at neither node, it moves no
// node's owner, so one pass leaves every rank owning a node of each of its 0D vessels. The
// red cells' transport needs it (a vessel's faces lie at the nodes their owners solve, and its
// rank reads them); it also leaves no rank linearising a vessel of no row of its own. A vessel
// that is its rank's last stays. Returns how many moved.
std::size_t hold_at_an_own_node(const Network& net, const LumpedOrder& whole, std::span<std::int32_t> vessel_rank,
                                int ranks);

// The halo of `rank` (one pi section a vessel). std::invalid_argument for a vessel of `whole`
// on no rank in [0, ranks).
LumpedHalo lumped_halo(const Network& net, const LumpedOrder& whole, std::span<const std::int32_t> vessel_rank,
                       int ranks, int rank);

// A step's collective calls, carried by the caller (over MPI: PETSc's solve and reductions).
struct LumpedHaloLink {
  // The least of every rank's key (a lumen closing: its vessel; none: the largest int64).
  std::function<std::int64_t(std::int64_t key)> least;
  // The step's system solved: per edge its conductance, per node its shunt and right-hand
  // side (the owner's rows; a ghost's are not read), x per node out, ghosts included.
  std::function<void(std::span<const double> conductance, std::span<const double> shunt, std::span<const double> rhs,
                     std::span<double> x)>
      solve;
  // The last solve's system again with another right-hand side (per node, the owner's rows).
  std::function<void(std::span<const double> rhs, std::span<double> x)> solve_again;
  // values per node: the owned nodes' in, every ghost's from its owner out.
  std::function<void(std::span<double> values)> fill_ghosts;
  // Each value summed over the ranks (in place, every rank's result the same bits).
  std::function<void(std::span<double> values)> sum;
};

// A rank's system as its link's solver numbers it: per node its key (its network node, or
// network nodes + outlet for a capacitor), every key's rank (LumpedHalo::key_rank), the edges.
// Copies: a solver may keep them.
struct LumpedHaloSystem {
  std::vector<std::int64_t> node_key;
  std::vector<std::int32_t> key_rank, a, b;
};

}  // namespace hemotree
