// One harmonic's nodal system of any graph (network_flow/harmonic_system.hpp's form: a
// two-port per edge, a shunt and a current per node) over the ranks of the MPI session, by
// PETSc: what a network with loops needs where a tree's distributed elimination
// (mpi_harmonic_tree.hpp) does not apply.
//
// PETSc here is Debian's real build, so each complex potential x = u + i v is two real
// unknowns, and each complex entry z of the system the 2 x 2 real block [Re z, -Im z; Im z,
// Re z]. Each node's two rows are its owner rank's; each rank adds the two-ports of its own
// edges and the shunts and currents of its own nodes, PETSc carrying what lands on another
// rank's rows. The system is complex symmetric where the two-ports are reciprocal, never
// Hermitian, and its real form is indefinite: conjugate gradients do not apply, and hypre's
// algebraic multigrid is made for M-matrices, which the real form of a wave's admittances is
// not. So it is factorised: LU by MUMPS (distributed, direct), its true relative residual
// checked against 1e-10. PETSC_OPTIONS may choose another method (bench/README.md compares).
//
// The matrix, its pattern and the solver are made by the first solve and kept: each later
// solve (the next harmonic) refills the values, and MUMPS factorises them again on the first
// one's analysis (its ordering and symbolic factorisation, the same pattern's): 11 solves
// on a 40,000-node mesh took 2.5 s of such analyses.
//
// For now every rank holds the whole graph's arrays (as it holds the whole network) and
// receives every node's potential.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "network_flow/harmonic_system.hpp"

namespace hemotree {

struct PetscObjects;

class PetscHarmonicNetwork {
 public:
  // The graph of `nodes` nodes and edges (a[e], b[e]); node_owner, edge_owner: each one's
  // rank; node_name: each node's name in a refusal (a network's node ids; empty: its index).
  // std::invalid_argument for sizes that do not match or a rank outside the session's.
  // Collective (starts PETSc on the MPI session once).
  PetscHarmonicNetwork(std::size_t nodes, std::span<const std::int32_t> a, std::span<const std::int32_t> b,
                       std::span<const std::int32_t> node_owner, std::span<const std::int32_t> edge_owner,
                       std::span<const std::int64_t> node_name = {});
  ~PetscHarmonicNetwork();
  PetscHarmonicNetwork(const PetscHarmonicNetwork&) = delete;
  PetscHarmonicNetwork& operator=(const PetscHarmonicNetwork&) = delete;

  // edge: per edge, read where this rank owns it (the currents into its ends: aa x_a + ab x_b
  // into a, ba x_a + bb x_b into b); shunt and current: per node, read where it owns the node;
  // potential: every node's, out on every rank. Collective. InputError, every rank's alike,
  // where the solve leaves a true relative residual above 1e-10 (a part of the network with
  // no admittance to ground, whose system is singular; PETSC_OPTIONS that ask too little).
  void solve(std::span<const TwoPort> edge, std::span<const Complex> shunt, std::span<const Complex> current,
             std::span<Complex> potential);
  const std::string& method() const { return method_; }  // e.g. "preonly with lu (mumps)"
  int iterations() const { return iterations_; }

 private:
  std::size_t nodes_;
  std::vector<std::int32_t> a_, b_, node_owner_, edge_owner_;
  std::vector<std::int64_t> node_name_;
  std::vector<std::int64_t> row_;  // per node: its first row (two a node), rank by rank
  std::int64_t first_row_ = 0, rows_ = 0, all_rows_ = 0;  // this rank's rows: [first, first + rows)
  std::vector<std::int32_t> in_block_, off_block_;        // per row of this rank: entries to preallocate
  std::string method_;
  int iterations_ = 0;
  std::unique_ptr<PetscObjects> held_;  // the matrix and solver, from the first solve on
  // Collective<InputError> where a connected part has nothing to ground (the system is then
  // singular, and an LU may not say so). Collective.
  void refuse_ungrounded(std::span<const TwoPort> edge, std::span<const Complex> shunt) const;
};

}  // namespace hemotree
