// A tree's harmonic system (network_flow/harmonic_system.hpp) solved over the ranks of an
// MPI communicator: the arithmetic of distributed/harmonic_tree_share.hpp, one gather of
// every share's roots to the top's rank and one scatter of their potentials back a solve
// (distributed/root_exchange.hpp), so the potentials are the whole system's bit for bit for
// any number of ranks. Each harmonic of a periodic state is one solve.
//
// A rank holds the nodes of its share and, on the top's rank, the top's after them
// (TreeCut::held_nodes): its arrays run over nodes(), in that order.
#pragma once

#include <complex>
#include <cstdint>
#include <span>
#include <vector>

#include <mpi.h>

#include "distributed/harmonic_tree_share.hpp"
#include "distributed/root_exchange.hpp"

namespace hemotree {

class MpiHarmonicTree {
 public:
  // Collective over comm, whose size must be cut.ranks. cut: of the harmonic system's edges.
  MpiHarmonicTree(MPI_Comm comm, const TreeCut& cut);
  std::span<const std::int32_t> nodes() const { return nodes_; }
  // The parent of each share root of this rank (TreeCut::roots[rank] order) and its potential
  // after the last solve: what a vessel into the share needs of the node above it.
  std::span<const std::int32_t> root_parents() const { return root_parents_; }
  std::span<const Complex> root_parent_potentials() const { return root_parent_potential_; }
  // On the top's rank, every share root (TreeCut::roots, rank after rank) and its potential
  // after the last solve; empty elsewhere.
  std::span<const std::int32_t> share_roots() const { return share_roots_; }
  std::span<const Complex> share_root_potentials() const { return share_root_potential_; }

  // Per node of this rank: its shunt (its diagonal before any edge's term), its edge to its
  // parent (unread at a root of the forest), its current in and its potential out.
  // Collective. A zero pivot, or numbers of the wrong count, on any rank: thrown on every rank
  // alike (mpi/session.hpp's Collective<std::invalid_argument>), that rank's words.
  void solve(std::span<const Complex> shunt, std::span<const EdgeToParent> edge, std::span<Complex> x);

  const RootExchange::Traffic& traffic() const { return exchange_.traffic(); }

 private:
  int rank_ = 0;
  std::vector<std::int32_t> nodes_, root_parents_;
  std::vector<Complex> root_parent_potential_;
  std::size_t share_size_ = 0;
  HarmonicTreeShare share_;
  std::vector<HarmonicTreeTop> top_;          // one, on the top's rank
  std::vector<std::int32_t> parent_of_slot_;  // top's rank: per share root, its parent among the top's own nodes
  std::vector<std::int32_t> share_roots_;     // top's rank: every share root, by slot
  std::vector<Complex> share_root_potential_;
  RootExchange exchange_;
};

}  // namespace hemotree
