// A tree's nodal system solved over the ranks of an MPI communicator (the arithmetic:
// distributed/tree_share.hpp): per factorisation and solve one gather of every share's roots
// to the top's rank and one scatter of their potentials back, in rank order, so the
// potentials are the whole system's bit for bit for any number of ranks.
//
// A rank holds the nodes of its share and, on the top's rank, the top's after them
// (TreeCut::held_nodes): its arrays run over nodes(), in that order.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <mpi.h>

#include "distributed/root_exchange.hpp"
#include "distributed/tree_share.hpp"

namespace hemotree {

class MpiTreeSystem {
 public:
  // Collective over comm, whose size must be cut.ranks.
  MpiTreeSystem(MPI_Comm comm, const TreeCut& cut);
  int rank() const { return rank_; }
  std::span<const std::int32_t> nodes() const { return nodes_; }
  // The parent of each share root of this rank, in the order of TreeCut::roots[rank], and its
  // potential after the last solve (0 where a root has none): what a vessel into the share
  // needs of the node above it.
  std::span<const std::int32_t> root_parents() const { return root_parents_; }
  std::span<const double> root_parent_potentials() const { return root_parent_potential_; }

  // Per node of this rank: the conductance of its edge to its parent (unread at a root of
  // the whole forest), its shunt; x: the right-hand side in, the potentials out. Collective.
  // Returns -1, or the node (of the whole forest) that names a component with no path to
  // ground, the same on every rank. Numbers one rank's system refuses (NodalSystem's
  // std::invalid_argument), or any other failure of one rank's part, are thrown on every rank
  // alike (mpi/session.hpp's Collective<std::invalid_argument>): that rank's words, "rank K: "
  // before them where K > 0.
  std::int64_t factorize_solve(std::span<const double> conductance, std::span<const double> shunt, std::span<double> x);
  // The same right-hand side in, potentials out, with the last factorisation (refused on
  // every rank where it did not succeed on every rank). Collective.
  void solve(std::span<double> x);

  // What this rank's exchanges have cost so far (a gather and a scatter a solve).
  using Traffic = RootExchange::Traffic;
  const Traffic& traffic() const { return exchange_.traffic(); }

 private:
  int rank_ = 0, top_rank_ = 0;
  std::vector<std::int32_t> nodes_, root_parents_;
  std::vector<double> root_parent_potential_;
  std::size_t share_size_ = 0;
  TreeShare share_;
  std::vector<TreeTop> top_;  // one, on the top's rank
  std::vector<std::int32_t> parent_of_slot_;  // top's rank: per share root, its parent among the top's own nodes
  RootExchange exchange_;
  bool factorized_ = false;  // the last factorisation succeeded on every rank
  std::int64_t exchange(std::span<const double> conductance, std::span<const double> shunt, std::span<double> x,
                        bool factorizing);
};

}  // namespace hemotree
