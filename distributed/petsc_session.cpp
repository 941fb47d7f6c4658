#include "distributed/petsc_session.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "core/errors.hpp"
#include "mpi/session.hpp"

namespace hemotree {

void petsc_check(PetscErrorCode code, const char* what) {
  if (code == 0) return;
  const char* reason = nullptr;
  PetscErrorMessage(code, &reason, nullptr);
  throw std::runtime_error(std::string("PETSc: ") + what + " failed: " + (reason ? reason : "error " + std::to_string(code)));
}

void petsc_options_check(PetscErrorCode code) {
  if (code == 0) return;
  const char* reason = nullptr;
  PetscErrorMessage(code, &reason, nullptr);
  throw InputError(std::string("PETSC_OPTIONS: ") + (reason ? reason : "refused by PETSc"));
}

void start_petsc() {
  PetscBool started = PETSC_FALSE;
  petsc_check(PetscInitialized(&started), "PetscInitialized");
  if (started) return;
  petsc_check(PetscInitializeNoArguments(), "PetscInitialize");
  petsc_check(PetscPushErrorHandler(PetscReturnErrorHandler, nullptr), "PetscPushErrorHandler");
  at_session_end([] { PetscFinalize(); });
}

PetscRows petsc_rows(std::span<const std::int32_t> owner, std::span<const unsigned char> skip, int per_node) {
  const int ranks = world_size(), rank = world_rank();
  auto rows_of = [&](std::size_t i) { return skip.empty() || !skip[i] ? per_node : 0; };
  std::vector<std::int64_t> count(static_cast<std::size_t>(ranks) + 1, 0);
  for (std::size_t i = 0; i < owner.size(); ++i) count[static_cast<std::size_t>(owner[i]) + 1] += rows_of(i);
  for (int r = 0; r < ranks; ++r) count[static_cast<std::size_t>(r) + 1] += count[static_cast<std::size_t>(r)];
  PetscRows rows;
  rows.first = count[static_cast<std::size_t>(rank)];
  rows.count = count[static_cast<std::size_t>(rank) + 1] - rows.first;
  rows.all = count.back();
  rows.row.assign(owner.size(), -1);
  std::vector<std::int64_t> next(count.begin(), count.end() - 1);
  for (std::size_t i = 0; i < owner.size(); ++i)
    if (rows_of(i) > 0) {
      rows.row[i] = next[static_cast<std::size_t>(owner[i])];
      next[static_cast<std::size_t>(owner[i])] += rows_of(i);
    }
  return rows;
}

Mat petsc_matrix(PetscInt rows, PetscInt all, std::vector<PetscInt> in_block, std::vector<PetscInt> off_block) {
  for (std::size_t k = 0; k < in_block.size(); ++k) {
    in_block[k] = std::min(in_block[k], rows);
    off_block[k] = std::min(off_block[k], all - rows);
  }
  Mat matrix = nullptr;
  petsc_check(MatCreate(PETSC_COMM_WORLD, &matrix), "MatCreate");
  petsc_check(MatSetSizes(matrix, rows, rows, all, all), "MatSetSizes");
  petsc_check(MatSetType(matrix, MATAIJ), "MatSetType");
  petsc_check(MatSeqAIJSetPreallocation(matrix, 0, in_block.data()), "MatSeqAIJSetPreallocation");
  petsc_check(MatMPIAIJSetPreallocation(matrix, 0, in_block.data(), 0, off_block.data()), "MatMPIAIJSetPreallocation");
  return matrix;
}

namespace {
void assemble(Mat matrix) {
  petsc_check(MatAssemblyBegin(matrix, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
  petsc_check(MatAssemblyEnd(matrix, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
}
void set_rhs(Vec rhs, std::span<const double> local_rhs) {
  PetscScalar* values = nullptr;
  petsc_check(VecGetArray(rhs, &values), "VecGetArray");
  std::copy(local_rhs.begin(), local_rhs.end(), values);
  petsc_check(VecRestoreArray(rhs, &values), "VecRestoreArray");
}
}  // namespace

void petsc_refill(PetscObjects& o, std::span<const double> local_rhs) {
  assemble(o.matrix);
  set_rhs(o.rhs, local_rhs);
}

PC petsc_prepare(PetscObjects& o, std::span<const double> local_rhs, KSPType type) {
  assemble(o.matrix);
  petsc_check(MatCreateVecs(o.matrix, &o.x, &o.rhs), "MatCreateVecs");
  set_rhs(o.rhs, local_rhs);
  petsc_check(KSPCreate(PETSC_COMM_WORLD, &o.solver), "KSPCreate");
  petsc_check(KSPSetOperators(o.solver, o.matrix, o.matrix), "KSPSetOperators");
  petsc_check(KSPSetType(o.solver, type), "KSPSetType");
  PC preconditioner = nullptr;
  petsc_check(KSPGetPC(o.solver, &preconditioner), "KSPGetPC");
  return preconditioner;
}

std::string petsc_method(KSP solver) {
  KSPType ksp_type = nullptr;
  PCType pc_type = nullptr;
  PC preconditioner = nullptr;
  MatSolverType factor = nullptr;
  petsc_check(KSPGetType(solver, &ksp_type), "KSPGetType");
  petsc_check(KSPGetPC(solver, &preconditioner), "KSPGetPC");
  petsc_check(PCGetType(preconditioner, &pc_type), "PCGetType");
  if (PCFactorGetMatSolverType(preconditioner, &factor) != 0) factor = nullptr;  // not a factorisation
  return std::string(ksp_type ? ksp_type : "?") + " with " + (pc_type ? pc_type : "?") +
         (factor ? std::string(" (") + factor + ")" : std::string());
}

PetscOutcome petsc_solve(PetscObjects& o) {
  petsc_options_check(KSPSetFromOptions(o.solver));
  if (KSPSolve(o.solver, o.rhs, o.x) != 0) petsc_check(VecSet(o.x, 0.0), "VecSet");
  PetscOutcome out;
  petsc_check(KSPGetConvergedReason(o.solver, &out.reason), "KSPGetConvergedReason");
  PetscInt iterations = 0;
  petsc_check(KSPGetIterationNumber(o.solver, &iterations), "KSPGetIterationNumber");
  out.iterations = static_cast<int>(iterations);
  out.method = petsc_method(o.solver);
  PetscReal residual = 0, scale = 0;
  Vec r = nullptr;  // b - A x (o.everywhere is the solution's, where a solver keeps it)
  petsc_check(VecDuplicate(o.rhs, &r), "VecDuplicate");
  PetscErrorCode code = MatMult(o.matrix, o.x, r);
  if (code == 0) code = VecAYPX(r, -1.0, o.rhs);
  if (code == 0) code = VecNorm(r, NORM_2, &residual);
  VecDestroy(&r);
  petsc_check(code, "the residual");
  petsc_check(VecNorm(o.rhs, NORM_2, &scale), "VecNorm");
  out.relative = scale > 0 ? residual / scale : residual;
  return out;
}

void petsc_read_everywhere(PetscObjects& o, const std::function<void(const PetscScalar*)>& read) {
  if (!o.to_all) petsc_check(VecScatterCreateToAll(o.x, &o.to_all, &o.everywhere), "VecScatterCreateToAll");
  petsc_check(VecScatterBegin(o.to_all, o.x, o.everywhere, INSERT_VALUES, SCATTER_FORWARD), "VecScatterBegin");
  petsc_check(VecScatterEnd(o.to_all, o.x, o.everywhere, INSERT_VALUES, SCATTER_FORWARD), "VecScatterEnd");
  const PetscScalar* values = nullptr;
  petsc_check(VecGetArrayRead(o.everywhere, &values), "VecGetArrayRead");
  read(values);
  petsc_check(VecRestoreArrayRead(o.everywhere, &values), "VecRestoreArrayRead");
}

}  // namespace hemotree
