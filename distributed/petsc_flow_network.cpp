#include "distributed/petsc_flow_network.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

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
  const int ranks = world_size(), rank = world_rank();
  // The free nodes numbered rank by rank, each rank's in the order of the nodes.
  std::vector<std::int64_t> count(static_cast<std::size_t>(ranks) + 1, 0);
  for (std::size_t i = 0; i < nodes; ++i)
    if (!prescribed_[i]) {
      if (owner_[i] < 0 || owner_[i] >= ranks)
        throw std::invalid_argument("PetscFlowNetwork: node " + std::to_string(i) + " on rank " + std::to_string(owner_[i]));
      ++count[static_cast<std::size_t>(owner_[i]) + 1];
    }
  for (int r = 0; r < ranks; ++r) count[static_cast<std::size_t>(r) + 1] += count[static_cast<std::size_t>(r)];
  first_row_ = count[static_cast<std::size_t>(rank)];
  rows_ = count[static_cast<std::size_t>(rank) + 1] - first_row_;
  all_rows_ = count.back();
  row_.assign(nodes, -1);
  std::vector<std::int64_t> next(count.begin(), count.end() - 1);
  for (std::size_t i = 0; i < nodes; ++i)
    if (!prescribed_[i]) row_[i] = next[static_cast<std::size_t>(owner_[i])]++;
}

PetscFlowNetwork::~PetscFlowNetwork() = default;

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
  std::vector<PetscInt> in_block(local, 1), off_block(local, 0);  // preallocation
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
        (owner_[j] == rank ? in_block : off_block)[k] += 1;
      }
    }
  }
  // PETSc's calls are collective: a failure there (a bad PETSC_OPTIONS, say) is every rank's
  // alike, passed on once all have left them (mpi/session.hpp's on_every_rank).
  PetscObjects o;
  KSPConvergedReason reason = KSP_CONVERGED_ITERATING;
  PetscReal residual = 0, scale = 0;
  on_every_rank([&] {
  const auto n = static_cast<PetscInt>(rows_), all = static_cast<PetscInt>(all_rows_);
  petsc_check(MatCreate(PETSC_COMM_WORLD, &o.matrix), "MatCreate");
  petsc_check(MatSetSizes(o.matrix, n, n, all, all), "MatSetSizes");
  petsc_check(MatSetType(o.matrix, MATAIJ), "MatSetType");
  for (std::size_t k = 0; k < local; ++k) {  // parallel edges share an entry: counted once each
    in_block[k] = std::min<PetscInt>(in_block[k], n);
    off_block[k] = std::min<PetscInt>(off_block[k], all - n);
  }
  petsc_check(MatSeqAIJSetPreallocation(o.matrix, 0, in_block.data()), "MatSeqAIJSetPreallocation");
  petsc_check(MatMPIAIJSetPreallocation(o.matrix, 0, in_block.data(), 0, off_block.data()), "MatMPIAIJSetPreallocation");
  petsc_check(MatSetOption(o.matrix, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE), "MatSetOption");
  for (std::size_t k = 0; k < local; ++k) {
    const auto r = static_cast<PetscInt>(first_row_ + static_cast<std::int64_t>(k));
    petsc_check(MatSetValue(o.matrix, r, r, diagonal[k], ADD_VALUES), "MatSetValue");
  }
  for (std::size_t q = 0; q < entry.size(); ++q)
    petsc_check(MatSetValue(o.matrix, entry_at[q].first, entry_at[q].second, entry[q], ADD_VALUES), "MatSetValue");
  petsc_check(MatAssemblyBegin(o.matrix, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
  petsc_check(MatAssemblyEnd(o.matrix, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
  petsc_check(MatSetOption(o.matrix, MAT_SPD, PETSC_TRUE), "MatSetOption");

  petsc_check(MatCreateVecs(o.matrix, &o.x, &o.rhs), "MatCreateVecs");
  PetscScalar* values = nullptr;
  petsc_check(VecGetArray(o.rhs, &values), "VecGetArray");
  std::copy(rhs.begin(), rhs.end(), values);
  petsc_check(VecRestoreArray(o.rhs, &values), "VecRestoreArray");

  petsc_check(KSPCreate(PETSC_COMM_WORLD, &o.solver), "KSPCreate");
  petsc_check(KSPSetOperators(o.solver, o.matrix, o.matrix), "KSPSetOperators");
  petsc_check(KSPSetType(o.solver, KSPCG), "KSPSetType");
  PC preconditioner = nullptr;
  petsc_check(KSPGetPC(o.solver, &preconditioner), "KSPGetPC");
  petsc_check(PCSetType(preconditioner, PCHYPRE), "PCSetType");
  petsc_check(PCHYPRESetType(preconditioner, "boomeramg"), "PCHYPRESetType");
  petsc_check(KSPSetTolerances(o.solver, 1e-13, 0.0, PETSC_DEFAULT, 2000), "KSPSetTolerances");
  // PETSC_OPTIONS may tune it: options it does not know are the user's input, refused so.
  petsc_options_check(KSPSetFromOptions(o.solver));
  petsc_check(KSPSolve(o.solver, o.rhs, o.x), "KSPSolve");
  petsc_check(KSPGetConvergedReason(o.solver, &reason), "KSPGetConvergedReason");
  PetscInt iterations = 0;
  petsc_check(KSPGetIterationNumber(o.solver, &iterations), "KSPGetIterationNumber");
  iterations_ = static_cast<int>(iterations);
  KSPType ksp_type = nullptr;
  PCType pc_type = nullptr;
  petsc_check(KSPGetType(o.solver, &ksp_type), "KSPGetType");
  petsc_check(PCGetType(preconditioner, &pc_type), "PCGetType");
  method_ = std::string(ksp_type ? ksp_type : "?") + " with " + (pc_type ? pc_type : "?");
  // The true residual, whatever the options asked of the solver: |b - A x| / |b|.
  petsc_check(VecDuplicate(o.rhs, &o.everywhere), "VecDuplicate");
  petsc_check(MatMult(o.matrix, o.x, o.everywhere), "MatMult");
  petsc_check(VecAYPX(o.everywhere, -1.0, o.rhs), "VecAYPX");
  petsc_check(VecNorm(o.everywhere, NORM_2, &residual), "VecNorm");
  petsc_check(VecNorm(o.rhs, NORM_2, &scale), "VecNorm");
  petsc_check(VecDestroy(&o.everywhere), "VecDestroy");
  });
  // Every rank's solver and norms say the same: refused alike.
  const double relative = scale > 0 ? residual / scale : residual;
  if (reason < 0 || !(relative <= 1e-10))
    throw Collective<InputError>("the distributed solve (PETSc's " + method_ + ") left a relative residual of " +
                                 std::to_string(relative) + " after " + std::to_string(iterations_) +
                                 " iterations (PETSc's reason " + std::to_string(reason) +
                                 "; 1e-10 is needed): resistances too far apart for it, or PETSC_OPTIONS that ask too "
                                 "little");

  // Every rank gets every free node's potential.
  petsc_check(VecScatterCreateToAll(o.x, &o.to_all, &o.everywhere), "VecScatterCreateToAll");
  petsc_check(VecScatterBegin(o.to_all, o.x, o.everywhere, INSERT_VALUES, SCATTER_FORWARD), "VecScatterBegin");
  petsc_check(VecScatterEnd(o.to_all, o.x, o.everywhere, INSERT_VALUES, SCATTER_FORWARD), "VecScatterEnd");
  const PetscScalar* solved = nullptr;
  petsc_check(VecGetArrayRead(o.everywhere, &solved), "VecGetArrayRead");
  for (std::size_t i = 0; i < nodes_; ++i)
    if (!prescribed_[i]) pressure[i] = solved[row_[i]];
  petsc_check(VecRestoreArrayRead(o.everywhere, &solved), "VecRestoreArrayRead");
}

}  // namespace hemotree
