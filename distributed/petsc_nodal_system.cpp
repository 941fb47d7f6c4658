#include "distributed/petsc_nodal_system.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>

#include <mpi.h>
#include <petscksp.h>

#include "core/errors.hpp"
#include "core/units.hpp"
#include "distributed/petsc_session.hpp"
#include "mpi/session.hpp"

namespace hemotree {

namespace {

// from's values at every node a rank holds, through the scatter to them, handed to read.
void scatter_to_nodes(VecScatter to_nodes, Vec from, Vec local, const std::function<void(const PetscScalar*)>& read) {
  petsc_check(VecScatterBegin(to_nodes, from, local, INSERT_VALUES, SCATTER_FORWARD), "VecScatterBegin");
  petsc_check(VecScatterEnd(to_nodes, from, local, INSERT_VALUES, SCATTER_FORWARD), "VecScatterEnd");
  const PetscScalar* held = nullptr;
  petsc_check(VecGetArrayRead(local, &held), "VecGetArrayRead");
  read(held);
  petsc_check(VecRestoreArrayRead(local, &held), "VecRestoreArrayRead");
}

}  // namespace

struct PetscNodalSystem::Objects {
  Mat matrix = nullptr;
  Vec x = nullptr, rhs = nullptr, residual = nullptr, owned = nullptr, local = nullptr, guess = nullptr;
  IS rows = nullptr;
  VecScatter to_nodes = nullptr;
  KSP solver = nullptr;
  ~Objects() {
    // Not after PETSc has ended (the session's end: a solver outliving its run).
    PetscBool finalized = PETSC_TRUE;
    if (PetscFinalized(&finalized) != 0 || finalized) return;
    if (solver) KSPDestroy(&solver);
    if (to_nodes) VecScatterDestroy(&to_nodes);
    if (rows) ISDestroy(&rows);
    for (Vec* v : {&x, &rhs, &residual, &owned, &local, &guess})
      if (*v) VecDestroy(v);
    if (matrix) MatDestroy(&matrix);
  }
};

PetscNodalSystem::PetscNodalSystem(std::span<const std::int32_t> key_rank, std::span<const std::int64_t> node_key,
                                   std::span<const std::int32_t> a, std::span<const std::int32_t> b)
    : o_(std::make_unique<Objects>()), a_(a.begin(), a.end()), b_(b.begin(), b.end()) {
  const std::size_t nodes = node_key.size();
  if (a.size() != b.size()) throw std::invalid_argument("PetscNodalSystem: two nodes per edge");
  if (key_rank.size() > static_cast<std::size_t>(std::numeric_limits<PetscInt>::max()))
    throw std::invalid_argument("PetscNodalSystem: more keys than PETSc's indices hold");
  start_petsc();
  const int rank = world_rank();
  std::vector<unsigned char> no_node(key_rank.size());
  for (std::size_t i = 0; i < key_rank.size(); ++i) no_node[i] = key_rank[i] < 0;
  const PetscRows rows = petsc_rows(key_rank, no_node, 1);
  first_row_ = rows.first;
  rows_ = rows.count;
  row_.resize(nodes);
  own_.resize(nodes);
  local_row_.assign(nodes, -1);
  std::vector<unsigned char> seen(static_cast<std::size_t>(rows_), 0);
  for (std::size_t k = 0; k < nodes; ++k) {
    const std::int64_t key = node_key[k];
    if (key < 0 || static_cast<std::size_t>(key) >= key_rank.size() || key_rank[static_cast<std::size_t>(key)] < 0)
      throw std::invalid_argument("PetscNodalSystem: node " + std::to_string(k) + " has key " + std::to_string(key) +
                                  ", which no rank owns");
    row_[k] = rows.row[static_cast<std::size_t>(key)];
    own_[k] = key_rank[static_cast<std::size_t>(key)] == rank;
    if (!own_[k]) continue;
    local_row_[k] = row_[k] - first_row_;
    if (seen[static_cast<std::size_t>(local_row_[k])]++)
      throw std::invalid_argument("PetscNodalSystem: key " + std::to_string(key) + " held twice");
  }
  // A row of this rank's that no node here holds would be empty: the system singular.
  if (const auto held = static_cast<std::int64_t>(std::count(seen.begin(), seen.end(), 1)); held != rows_)
    throw std::invalid_argument("PetscNodalSystem: " + std::to_string(rows_ - held) + " of this rank's " +
                                std::to_string(rows_) + " keys held by no node here");
  for (std::size_t e = 0; e < a_.size(); ++e)
    for (const std::int32_t k : {a_[e], b_[e]})
      if (k < 0 || static_cast<std::size_t>(k) >= nodes || a_[e] == b_[e])
        throw std::invalid_argument("PetscNodalSystem: edge " + std::to_string(e) + " joins nodes " + std::to_string(a_[e]) +
                                    " and " + std::to_string(b_[e]) + " of " + std::to_string(nodes));

  Objects& o = *o_;
  const auto n = static_cast<PetscInt>(rows_), all = static_cast<PetscInt>(rows.all);
  // The pattern: each owned row's diagonal and an entry per edge at it (parallel edges share
  // one: counted twice, an upper bound).
  std::vector<PetscInt> in_block(static_cast<std::size_t>(n), 1), off_block(static_cast<std::size_t>(n), 0);
  for (std::size_t e = 0; e < a_.size(); ++e)
    for (const bool from_a : {true, false}) {
      const auto i = static_cast<std::size_t>(from_a ? a_[e] : b_[e]), j = static_cast<std::size_t>(from_a ? b_[e] : a_[e]);
      if (own_[i]) (own_[j] ? in_block : off_block)[static_cast<std::size_t>(local_row_[i])] += 1;
    }
  o.matrix = petsc_matrix(n, all, std::move(in_block), std::move(off_block));
  for (std::size_t k = 0; k < nodes; ++k)
    if (own_[k]) petsc_check(MatSetValue(o.matrix, row_[k], row_[k], 0.0, INSERT_VALUES), "MatSetValue");
  for (std::size_t e = 0; e < a_.size(); ++e)
    for (const bool from_a : {true, false}) {
      const auto i = static_cast<std::size_t>(from_a ? a_[e] : b_[e]), j = static_cast<std::size_t>(from_a ? b_[e] : a_[e]);
      if (own_[i]) petsc_check(MatSetValue(o.matrix, row_[i], row_[j], 0.0, INSERT_VALUES), "MatSetValue");
    }
  petsc_check(MatAssemblyBegin(o.matrix, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
  petsc_check(MatAssemblyEnd(o.matrix, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
  // The pattern is the graph's: a value outside it is a bug, not a new entry.
  petsc_check(MatSetOption(o.matrix, MAT_NEW_NONZERO_LOCATION_ERR, PETSC_TRUE), "MatSetOption");
  petsc_check(MatCreateVecs(o.matrix, &o.x, &o.rhs), "MatCreateVecs");
  petsc_check(VecDuplicate(o.rhs, &o.residual), "VecDuplicate");
  petsc_check(VecDuplicate(o.rhs, &o.owned), "VecDuplicate");
  petsc_check(VecDuplicate(o.rhs, &o.guess), "VecDuplicate");
  // Every node this rank holds, owned or ghost, from the rows of the whole.
  std::vector<PetscInt> held(row_.begin(), row_.end());
  petsc_check(VecCreateSeq(PETSC_COMM_SELF, static_cast<PetscInt>(nodes), &o.local), "VecCreateSeq");
  petsc_check(ISCreateGeneral(PETSC_COMM_SELF, static_cast<PetscInt>(nodes), held.data(), PETSC_COPY_VALUES, &o.rows),
              "ISCreateGeneral");
  petsc_check(VecScatterCreate(o.x, o.rows, o.local, nullptr, &o.to_nodes), "VecScatterCreate");
  petsc_check(KSPCreate(PETSC_COMM_WORLD, &o.solver), "KSPCreate");
  petsc_check(KSPSetOperators(o.solver, o.matrix, o.matrix), "KSPSetOperators");
  // GMRES on the true residual (preconditioned on the right), from the last step's solution,
  // with BoomerAMG (hypre's algebraic multigrid) made for an earlier step's matrix: the
  // conductances move little from step to step, so a few iterations reach the tolerance. The
  // system is a weighted Laplacian plus a positive diagonal, the M-matrix multigrid is made
  // for, and nearly singular where few nodes are held (the mesentery: one pressure, 35 flows).
  // Measured (bench/README.md): 2.5 to 3 iterations a step on the mesentery and on capillary
  // meshes of 10,000 to 160,000 nodes over 2 to 8 ranks. Block Jacobi with ILU(0) took 1.4
  // to 1.5 times less time on the meshes, but on the mesentery 13 iterations a step over 2
  // ranks and stalled over 3; MUMPS's LU as preconditioner took 3.6 times as long.
  petsc_check(KSPSetType(o.solver, KSPGMRES), "KSPSetType");
  petsc_check(KSPSetPCSide(o.solver, PC_RIGHT), "KSPSetPCSide");
  petsc_check(KSPSetTolerances(o.solver, relative_tolerance, 0.0, PETSC_DEFAULT, most_iterations), "KSPSetTolerances");
  petsc_check(KSPSetInitialGuessNonzero(o.solver, PETSC_TRUE), "KSPSetInitialGuessNonzero");
  // A held pressure's shunt is some 1e10 times its node's other terms: on the system as it is,
  // a residual small against |b| says nothing of the other rows. Scaled symmetrically by its
  // diagonal, every row counts alike (PETSc scales, solves and unscales).
  petsc_check(KSPSetDiagonalScale(o.solver, PETSC_TRUE), "KSPSetDiagonalScale");
  petsc_check(KSPSetDiagonalScaleFix(o.solver, PETSC_TRUE), "KSPSetDiagonalScaleFix");
  PC preconditioner = nullptr;
  petsc_check(KSPGetPC(o.solver, &preconditioner), "KSPGetPC");
  petsc_check(PCSetType(preconditioner, PCHYPRE), "PCSetType");
  petsc_check(PCHYPRESetType(preconditioner, "boomeramg"), "PCHYPRESetType");
  petsc_options_check(KSPSetFromOptions(o.solver));
  method_ = petsc_method(o.solver);
}

PetscNodalSystem::~PetscNodalSystem() = default;

void PetscNodalSystem::solve(std::span<const double> conductance, std::span<const double> shunt,
                             std::span<const double> rhs, std::span<double> x) {
  const std::size_t nodes = row_.size();
  if (conductance.size() != a_.size() || shunt.size() != nodes || rhs.size() != nodes || x.size() != nodes)
    throw std::invalid_argument("PetscNodalSystem::solve: a conductance per edge, a shunt, a right-hand side and x per node");
  const double started = MPI_Wtime();
  Objects& o = *o_;
  assemble(conductance, shunt);
  if (solves_ > 0) petsc_check(VecCopy(o.guess, o.x), "VecCopy");  // the last step's solution
  solve_rows(rhs, x, true);
  petsc_check(VecCopy(o.x, o.guess), "VecCopy");
  seconds_ += MPI_Wtime() - started;
}

void PetscNodalSystem::solve_again(std::span<const double> rhs, std::span<double> x) {
  if (rhs.size() != row_.size() || x.size() != row_.size())
    throw std::invalid_argument("PetscNodalSystem::solve_again: a right-hand side and x per node");
  if (solves_ == 0) throw std::logic_error("PetscNodalSystem::solve_again before a solve");
  const double started = MPI_Wtime();
  petsc_check(VecSet(o_->x, 0.0), "VecSet");
  solve_rows(rhs, x, false);
  seconds_ += MPI_Wtime() - started;
}

void PetscNodalSystem::assemble(std::span<const double> conductance, std::span<const double> shunt) {
  const std::size_t nodes = row_.size();
  Objects& o = *o_;
  // This rank's rows: the same entries as the pattern, their values anew.
  petsc_check(MatZeroEntries(o.matrix), "MatZeroEntries");
  for (std::size_t k = 0; k < nodes; ++k)
    if (own_[k]) petsc_check(MatSetValue(o.matrix, row_[k], row_[k], shunt[k], ADD_VALUES), "MatSetValue");
  for (std::size_t e = 0; e < a_.size(); ++e) {
    const double g = conductance[e];
    for (const bool from_a : {true, false}) {
      const auto i = static_cast<std::size_t>(from_a ? a_[e] : b_[e]), j = static_cast<std::size_t>(from_a ? b_[e] : a_[e]);
      if (!own_[i]) continue;
      petsc_check(MatSetValue(o.matrix, row_[i], row_[i], g, ADD_VALUES), "MatSetValue");
      petsc_check(MatSetValue(o.matrix, row_[i], row_[j], -g, ADD_VALUES), "MatSetValue");
    }
  }
  petsc_check(MatAssemblyBegin(o.matrix, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
  petsc_check(MatAssemblyEnd(o.matrix, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
}

void PetscNodalSystem::solve_rows(std::span<const double> rhs, std::span<double> x, bool step) {
  const std::size_t nodes = row_.size();
  Objects& o = *o_;
  PetscScalar* values = nullptr;
  petsc_check(VecGetArray(o.rhs, &values), "VecGetArray");
  for (std::size_t k = 0; k < nodes; ++k)
    if (own_[k]) values[local_row_[k]] = rhs[k];
  petsc_check(VecRestoreArray(o.rhs, &values), "VecRestoreArray");
  // The preconditioner of an earlier step while it serves (a few iterations), else made anew
  // from this step's matrix; a solve that does not converge with an old one is taken again
  // with a new one. A solve PETSc gives up (a part with no path to ground) leaves x zero: the
  // residual says so. GMRES may stall at rounding short of its tolerance: what counts is the
  // true residual below.
  KSPConvergedReason reason = KSP_CONVERGED_ITERATING;
  PetscInt iterations = 0;
  // A solve again reuses the step's preconditioner, made for this matrix or an earlier one.
  bool reused = reuse_ || !step;
  for (;;) {
    petsc_check(KSPSetReusePreconditioner(o.solver, reused ? PETSC_TRUE : PETSC_FALSE), "KSPSetReusePreconditioner");
    if (KSPSolve(o.solver, o.rhs, o.x) != 0) petsc_check(VecSet(o.x, 0.0), "VecSet");
    petsc_check(KSPGetConvergedReason(o.solver, &reason), "KSPGetConvergedReason");
    petsc_check(KSPGetIterationNumber(o.solver, &iterations), "KSPGetIterationNumber");
    if (!reused) ++setups_;
    if (!reused && step) fresh_iterations_ = static_cast<int>(iterations);
    if (reason >= 0 || !reused) break;
    reused = false;  // once more, with a preconditioner made for this matrix
    petsc_check(VecSet(o.x, 0.0), "VecSet");
  }
  // A step's solve decides the next step's preconditioner (a solve again, from zero, takes
  // more iterations than a step's from the last solution: it decides only where it made one).
  if (step) reuse_ = reason >= 0 && iterations <= fresh_iterations_ + more_iterations;
  else if (!reused) reuse_ = reason >= 0;
  iterations_ += static_cast<std::size_t>(iterations);
  // The true residual of the system scaled by its diagonal, D^-1/2 (b - A x) against D^-1/2 b.
  PetscReal residual = 0, scale = 0;
  petsc_check(MatMult(o.matrix, o.x, o.residual), "MatMult");
  petsc_check(VecAYPX(o.residual, -1.0, o.rhs), "VecAYPX");
  petsc_check(MatGetDiagonal(o.matrix, o.owned), "MatGetDiagonal");
  petsc_check(VecSqrtAbs(o.owned), "VecSqrtAbs");
  petsc_check(VecPointwiseDivide(o.residual, o.residual, o.owned), "VecPointwiseDivide");
  petsc_check(VecNorm(o.residual, NORM_2, &residual), "VecNorm");
  petsc_check(VecPointwiseDivide(o.residual, o.rhs, o.owned), "VecPointwiseDivide");
  petsc_check(VecNorm(o.residual, NORM_2, &scale), "VecNorm");
  const double relative = scale > 0 ? residual / scale : residual;
  ++solves_;
  // Every rank's norms and reason are the same: refused alike.
  if (!(relative <= most_residual))
    throw Collective<InputError>("the 0D step's distributed solve (PETSc's " + method_ + ") left a relative residual of " +
                                 format_rounded(relative) +
                                 " (PETSc's reason " + std::to_string(reason) +
                                 "; 1e-13 is needed): a part of the 0D vessels with no path to an outlet, or "
                                 "PETSC_OPTIONS that ask too little");
  scatter_to_nodes(o.to_nodes, o.x, o.local, [&](const PetscScalar* solved) { std::copy_n(solved, nodes, x.begin()); });
}


void PetscNodalSystem::fill_ghosts(std::span<double> values) {
  const std::size_t nodes = row_.size();
  if (values.size() != nodes) throw std::invalid_argument("PetscNodalSystem::fill_ghosts: a value per node");
  const double started = MPI_Wtime();
  Objects& o = *o_;
  PetscScalar* owned = nullptr;
  petsc_check(VecGetArray(o.owned, &owned), "VecGetArray");
  for (std::size_t k = 0; k < nodes; ++k)
    if (own_[k]) owned[local_row_[k]] = values[k];
  petsc_check(VecRestoreArray(o.owned, &owned), "VecRestoreArray");
  scatter_to_nodes(o.to_nodes, o.owned, o.local, [&](const PetscScalar* held) {
    for (std::size_t k = 0; k < nodes; ++k)
      if (!own_[k]) values[k] = held[k];
  });
  seconds_ += MPI_Wtime() - started;
}

}  // namespace hemotree
