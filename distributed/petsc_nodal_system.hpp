// network_flow/nodal_system.hpp's system, (sum_e g_e (u_a - u_b)(u_a - u_b)^T + diag(s)) x = b,
// over the ranks of the MPI session by PETSc, for a caller that solves it again and again
// with new conductances, shunts and right-hand sides on one graph (the implicit steps of a 0D
// system with loops: pulse/lumped_halo.hpp).
//
// Each rank holds some nodes: the rows it owns, and ghosts (nodes of its edges another rank
// owns). Every node has a key, and every rank knows every key's owner: the rows are numbered
// rank by rank, each rank's by key. The graph is fixed, so the matrix's pattern and MUMPS's
// analysis of it are made once; each solve refills the values of the rows a rank owns (its
// edges reach every edge of its nodes), solves the system scaled by its diagonal (a held
// pressure's shunt is 1e10 times its node's other terms) by GMRES from the last solution,
// preconditioned by BoomerAMG (hypre's algebraic multigrid) made for an earlier step's
// matrix and made anew when it no longer serves, and scatters the solution to every node a
// rank holds. PETSC_OPTIONS may choose another (-pc_type bjacobi: ILU(0) in each block).
// PETSC_OPTIONS may choose another solver; a solve whose true relative residual exceeds 1e-10
// is refused on every rank.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace hemotree {

class PetscNodalSystem {
 public:
  // key_rank: per key, its owner (-1: no node has it); node_key: per node this rank holds,
  // its key; edges (a[e], b[e]) by those nodes: every edge at a node it owns, with the edges'
  // conductances given at every solve. Collective.
  PetscNodalSystem(std::span<const std::int32_t> key_rank, std::span<const std::int64_t> node_key,
                   std::span<const std::int32_t> a, std::span<const std::int32_t> b);
  ~PetscNodalSystem();
  PetscNodalSystem(const PetscNodalSystem&) = delete;
  PetscNodalSystem& operator=(const PetscNodalSystem&) = delete;

  // conductance per edge, shunt and rhs per node (a ghost's not read); x per node out, every
  // ghost's too (x may alias rhs). Collective. Collective<InputError> where the solve fails
  // or leaves a true relative residual above 1e-10.
  void solve(std::span<const double> conductance, std::span<const double> shunt, std::span<const double> rhs,
             std::span<double> x);
  // The last solve's system with another right-hand side, from zero. Collective.
  void solve_again(std::span<const double> rhs, std::span<double> x);
  // values per node: each ghost's set to its owner's. Collective.
  void fill_ghosts(std::span<double> values);

  const std::string& method() const { return method_; }  // e.g. "preonly with lu (mumps)"
  std::size_t solves() const { return solves_; }
  std::size_t preconditioner_setups() const { return setups_; }
  std::size_t iterations() const { return iterations_; }          // over every solve
  double seconds() const { return seconds_; }  // inside solve and fill_ghosts, waiting included

 private:
  struct Objects;  // PETSc's, out of this header
  std::unique_ptr<Objects> o_;
  std::vector<unsigned char> own_;       // per node
  std::vector<std::int64_t> local_row_;  // per node: its row among this rank's, -1 for a ghost
  std::vector<std::int32_t> a_, b_;
  std::vector<std::int64_t> row_;        // per node: its global row
  std::int64_t first_row_ = 0, rows_ = 0;
  std::string method_;
  std::size_t solves_ = 0, setups_ = 0, iterations_ = 0;
  bool reuse_ = false;  // the preconditioner of an earlier step, at the next solve
  int fresh_iterations_ = 0;  // the last solve's with a preconditioner made for its matrix
  // Solved to a relative residual of 1e-15 of the scaled system, or as near as rounding lets
  // GMRES come (the one-process Cholesky's is about 1e-16: the results then agree to about
  // 1e-9). Refused above 1e-13: the scaled system's condition reaches 1e5 (the mesentery), and
  // a solve that stalled at 1e-10 moved its flows by 2e-5 of the largest. The preconditioner
  // made anew after a solve that took more_iterations more than the last with a new one.
  static constexpr double relative_tolerance = 1e-15, most_residual = 1e-13;
  static constexpr int most_iterations = 50, more_iterations = 2;
  double seconds_ = 0;
  void assemble(std::span<const double> conductance, std::span<const double> shunt);
  // rhs into x by the solver from o.x (step: a step's solve, which decides the next's
  // preconditioner), checked, scattered to every node held.
  void solve_rows(std::span<const double> rhs, std::span<double> x, bool step);
};

}  // namespace hemotree
