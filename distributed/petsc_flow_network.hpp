// The nodal system of any graph (loops, parallel edges) with pressures prescribed at some
// nodes (network_flow/flow_network.hpp's form) over the ranks of the MPI session, by PETSc:
// the free nodes split by their owner rank (a partition's: partition/), each rank assembling
// the rows of its own, and the symmetric positive definite system solved by conjugate
// gradients preconditioned with hypre's BoomerAMG (algebraic multigrid: a network's Laplacian
// is an M-matrix, the problem it was made for) to a relative residual of 1e-15, or as near as
// rounding lets it come (the true residual is checked at 1e-10). The potentials then agree
// with the one-process sparse Cholesky's to about 1e-13 relative (not bit for bit: the sums
// of a Krylov method run over the ranks' rows).
//
// Solved again and again (the steady phase separation's passes, hundreds on a capillary bed),
// it keeps the matrix's pattern, starts from the last solution, and keeps BoomerAMG's
// hierarchy while it serves (made anew after a solve two iterations longer than the last
// fresh one's, or where an old one does not converge): on a 40,000-node mesh 379 set-ups
// took 11 s of 40.
//
// For now every rank holds the whole graph's arrays (as it holds the whole network), assembles
// its own rows from them, and receives the whole solution.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace hemotree {

struct PetscObjects;

class PetscFlowNetwork {
 public:
  // The graph of `nodes` nodes and edges (a[e], b[e]); prescribed: per node; owner: per node,
  // its rank. Collective (initialises PETSc on the MPI session once).
  PetscFlowNetwork(std::size_t nodes, std::span<const std::int32_t> a, std::span<const std::int32_t> b,
                   std::span<const unsigned char> prescribed, std::span<const std::int32_t> owner);
  ~PetscFlowNetwork();
  PetscFlowNetwork(const PetscFlowNetwork&) = delete;
  PetscFlowNetwork& operator=(const PetscFlowNetwork&) = delete;

  // conductance: per edge, > 0; shunt, inflow: per node; pressure: the prescribed nodes'
  // values in, every node's out (on every rank). Collective. InputError, every rank's alike,
  // where the solve leaves a true relative residual above 1e-10 (whatever PETSC_OPTIONS asked).
  void solve(std::span<const double> conductance, std::span<const double> shunt, std::span<const double> inflow,
             std::span<double> pressure);
  int iterations() const { return iterations_; }  // of the last solve
  const std::string& method() const { return method_; }  // PETSc's solver and preconditioner, e.g. "cg with hypre"
  int preconditioner_setups() const { return setups_; }  // over every solve so far

 private:
  std::size_t nodes_;
  std::vector<std::int32_t> a_, b_, owner_;
  std::vector<unsigned char> prescribed_;
  std::vector<std::int64_t> row_;    // per node: its global row, -1 where prescribed
  std::int64_t first_row_ = 0, rows_ = 0, all_rows_ = 0;  // this rank's rows: [first, first + rows)
  int iterations_ = 0;
  std::string method_;
  // The matrix, vectors and solver from the first solve on; the preconditioner's state.
  std::unique_ptr<PetscObjects> held_;
  bool reuse_ = false;
  int fresh_iterations_ = 0, setups_ = 0;
  // The first solve's: the matrix's pattern (preallocation) and the solver. Collective.
  void make(std::span<const double> local_rhs);
};

}  // namespace hemotree
