#include "distributed/petsc_flow_network.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <mpi.h>
#include <petscksp.h>

#include "core/errors.hpp"
#include "distributed/petsc_session.hpp"
#include "mpi/session.hpp"

namespace hemotree {

PetscFlowNetwork::PetscFlowNetwork(std::size_t nodes, std::span<const std::int32_t> a, std::span<const std::int32_t> b,
                                   std::span<const unsigned char> prescribed, std::span<const std::int32_t> owner)
    : nodes_(nodes), a_(a.begin(), a.end()), b_(b.begin(), b.end()), owner_(owner.begin(), owner.end()),
      prescribed_(prescribed.begin(), prescribed.end()) {
  if (a.size() != b.size() || prescribed.size() != nodes || owner.size() != nodes)
    throw std::invalid_argument("PetscFlowNetwork: two nodes per edge, a flag and an owner per node");
  if (nodes > static_cast<std::size_t>(std::numeric_limits<PetscInt>::max()))
    throw std::invalid_argument("PetscFlowNetwork: more nodes than PETSc's indices hold");
  start_petsc();
  const int ranks = world_size();
  // The free nodes numbered rank by rank, each rank's in the order of the nodes.
  for (std::size_t i = 0; i < nodes; ++i)
    if (owner_[i] < 0 || owner_[i] >= ranks)
      throw std::invalid_argument("PetscFlowNetwork: node " + std::to_string(i) + " on rank " + std::to_string(owner_[i]));
  PetscRows rows = petsc_rows(owner_, prescribed_, 1);
  row_ = std::move(rows.row);
  first_row_ = rows.first;
  rows_ = rows.count;
  all_rows_ = rows.all;
}

PetscFlowNetwork::~PetscFlowNetwork() = default;

namespace {
// A preconditioner kept while a solve takes at most this many iterations more than the one
// it was made for (PetscNodalSystem's rule).
constexpr int more_iterations = 2;
constexpr int most_iterations = 500;
}  // namespace

void PetscFlowNetwork::make(std::span<const double> local_rhs) {
  const int rank = world_rank();
  auto mine = [&](std::size_t i) { return !prescribed_[i] && owner_[i] == rank; };
  const auto local = static_cast<std::size_t>(rows_);
  const auto n = static_cast<PetscInt>(rows_), all = static_cast<PetscInt>(all_rows_);
  std::vector<PetscInt> in_block(local, 1), off_block(local, 0);  // the diagonal, an entry per edge to a free node
  std::vector<std::pair<PetscInt, PetscInt>> off_diagonal;          // those entries' (row, column)
  for (std::size_t e = 0; e < a_.size(); ++e)
    for (const bool from_a : {true, false}) {
      const auto i = static_cast<std::size_t>(from_a ? a_[e] : b_[e]), j = static_cast<std::size_t>(from_a ? b_[e] : a_[e]);
      if (!mine(i) || prescribed_[j]) continue;
      (owner_[j] == rank ? in_block : off_block)[static_cast<std::size_t>(row_[i] - first_row_)] += 1;
      off_diagonal.emplace_back(static_cast<PetscInt>(row_[i]), static_cast<PetscInt>(row_[j]));
    }
  PetscObjects& o = *held_;
  o.matrix = petsc_matrix(n, all, std::move(in_block), std::move(off_block));  // (parallel edges counted apart: a little over)
  petsc_check(MatSetOption(o.matrix, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE), "MatSetOption");
  petsc_check(MatSetOption(o.matrix, MAT_SPD, PETSC_TRUE), "MatSetOption");
  // The pattern: every entry a solve sets, as zeros before the first assembly (which drops
  // the preallocation it does not see used: an entry added after it is a malloc).
  for (std::size_t k = 0; k < local; ++k) {
    const auto r = static_cast<PetscInt>(first_row_ + static_cast<std::int64_t>(k));
    petsc_check(MatSetValue(o.matrix, r, r, 0.0, ADD_VALUES), "MatSetValue");
  }
  for (const auto& [row, column] : off_diagonal) petsc_check(MatSetValue(o.matrix, row, column, 0.0, ADD_VALUES), "MatSetValue");
  const PC preconditioner = petsc_prepare(o, local_rhs, KSPCG);
  petsc_check(VecSet(o.x, 0.0), "VecSet");  // the first solve's start
  petsc_check(PCSetType(preconditioner, PCHYPRE), "PCSetType");
  petsc_check(PCHYPRESetType(preconditioner, "boomeramg"), "PCHYPRESetType");
  // As near the one-process Cholesky as rounding lets CG come: the phase separation's passes
  // feed each solve's flows to the next, and solves to 1e-13 from the last solution (true
  // residuals of 4e-14) took a capillary mesh's passes another way (347 passes, not 379, its
  // hematocrits 3e-8 apart). Where CG stalls short of it, the true residual decides (below).
  petsc_check(KSPSetTolerances(o.solver, 1e-15, 0.0, PETSC_DEFAULT, most_iterations), "KSPSetTolerances");
  petsc_check(KSPSetInitialGuessNonzero(o.solver, PETSC_TRUE), "KSPSetInitialGuessNonzero");  // the last solution
  petsc_options_check(KSPSetFromOptions(o.solver));  // PETSC_OPTIONS may tune it
}

void PetscFlowNetwork::solve(std::span<const double> conductance, std::span<const double> shunt,
                             std::span<const double> inflow, std::span<double> pressure) {
  if (conductance.size() != a_.size() || shunt.size() != nodes_ || inflow.size() != nodes_ || pressure.size() != nodes_)
    throw std::invalid_argument("PetscFlowNetwork::solve: a conductance per edge, a shunt, an inflow and a pressure per node");
  const int rank = world_rank();
  auto mine = [&](std::size_t i) { return !prescribed_[i] && owner_[i] == rank; };
  // This rank's rows: the diagonal (shunt and every edge's conductance), an entry -g per edge
  // to a free node, g p for an edge to a prescribed one on the right-hand side.
  const auto local = static_cast<std::size_t>(rows_);
  std::vector<double> diagonal(local, 0.0), rhs(local, 0.0);
  std::vector<std::pair<PetscInt, PetscInt>> entry_at;
  std::vector<double> entry;
  for (std::size_t i = 0; i < nodes_; ++i)
    if (mine(i)) {
      const auto k = static_cast<std::size_t>(row_[i] - first_row_);
      diagonal[k] += shunt[i];
      rhs[k] += inflow[i];
    }
  for (std::size_t e = 0; e < a_.size(); ++e) {
    const double g = conductance[e];
    for (const bool from_a : {true, false}) {
      const auto i = static_cast<std::size_t>(from_a ? a_[e] : b_[e]), j = static_cast<std::size_t>(from_a ? b_[e] : a_[e]);
      if (!mine(i)) continue;
      const auto k = static_cast<std::size_t>(row_[i] - first_row_);
      diagonal[k] += g;
      if (prescribed_[j]) {
        rhs[k] += g * pressure[j];
      } else {
        entry_at.emplace_back(static_cast<PetscInt>(row_[i]), static_cast<PetscInt>(row_[j]));
        entry.push_back(-g);
      }
    }
  }
  // PETSc's calls are collective: a failure there (a bad PETSC_OPTIONS, say) is every rank's
  // alike, passed on once all have left them (mpi/session.hpp's on_every_rank); the next
  // solve then starts afresh.
  const bool first = !held_;
  if (first) held_ = std::make_unique<PetscObjects>();
  PetscObjects& o = *held_;
  PetscOutcome outcome;
  bool solved = false;
  try {
    on_every_rank([&] {
      if (first) make(rhs);
      petsc_check(MatZeroEntries(o.matrix), "MatZeroEntries");
      for (std::size_t k = 0; k < local; ++k) {
        const auto r = static_cast<PetscInt>(first_row_ + static_cast<std::int64_t>(k));
        petsc_check(MatSetValue(o.matrix, r, r, diagonal[k], ADD_VALUES), "MatSetValue");
      }
      for (std::size_t q = 0; q < entry.size(); ++q)
        petsc_check(MatSetValue(o.matrix, entry_at[q].first, entry_at[q].second, entry[q], ADD_VALUES), "MatSetValue");
      petsc_refill(o, rhs);
      // The last solve's preconditioner while it serves; one that does not converge is made
      // anew for this matrix, the solve taken again from the last solution.
      bool reused = reuse_;
      // Converged, or stalled at rounding near it (the true residual: what counts).
      auto served = [&] { return outcome.reason >= 0 || outcome.relative <= 1e-13; };
      Vec start = nullptr;
      petsc_check(VecDuplicate(o.x, &start), "VecDuplicate");
      petsc_check(VecCopy(o.x, start), "VecCopy");
      for (;;) {
        petsc_check(KSPSetReusePreconditioner(o.solver, reused ? PETSC_TRUE : PETSC_FALSE), "KSPSetReusePreconditioner");
        outcome = petsc_solve(o);
        if (!reused) {
          ++setups_;
          fresh_iterations_ = outcome.iterations;
        }
        if (served() || !reused) break;
        reused = false;
        petsc_check(VecCopy(start, o.x), "VecCopy");
      }
      VecDestroy(&start);
      reuse_ = served() && outcome.iterations <= fresh_iterations_ + more_iterations;
    });
    solved = true;
  } catch (...) {
    held_.reset();
    reuse_ = false;
    throw;
  }
  iterations_ = outcome.iterations;
  method_ = outcome.method;
  const double relative = outcome.relative;
  // Every rank's norms say the same: refused alike.
  if (!solved || !(relative <= 1e-10)) {
    held_.reset();
    reuse_ = false;
    throw Collective<InputError>("the distributed solve (PETSc's " + method_ + ") left a relative residual of " +
                                 std::to_string(relative) + " after " + std::to_string(iterations_) +
                                 " iterations (PETSc's reason " + std::to_string(outcome.reason) +
                                 "; 1e-10 is needed): resistances too far apart for it, or PETSC_OPTIONS that ask too "
                                 "little");
  }

  // Every rank gets every free node's potential.
  petsc_read_everywhere(o, [&](const PetscScalar* solved_x) {
    for (std::size_t i = 0; i < nodes_; ++i)
      if (!prescribed_[i]) pressure[i] = solved_x[row_[i]];
  });
}

}  // namespace hemotree
