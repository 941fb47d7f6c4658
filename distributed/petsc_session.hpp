// PETSc on the MPI session, for the solvers that use it (petsc_flow_network,
// petsc_harmonic_network): started once, finalised before MPI when the session ends, its
// error codes as exceptions (its own printing of a traceback turned off), and the objects of
// a solve.
#pragma once

#include <functional>
#include <span>
#include <string>
#include <vector>

#include <petscksp.h>

namespace hemotree {

void start_petsc();
// Throws std::runtime_error "PETSc: WHAT failed: its message" for a non-zero code.
void petsc_check(PetscErrorCode code, const char* what);
// PETSC_OPTIONS given to a solver (KSPSetFromOptions' code): InputError where it refuses them.
void petsc_options_check(PetscErrorCode code);

// The rows of a nodal system over the ranks: per node `per_node` rows (none where skip[i] is
// set; skip may be empty), numbered rank by rank (owner[i]: its rank), each rank's nodes in
// their order. row: per node its first row, -1 where skipped; this rank's rows [first,
// first + count); all of them.
struct PetscRows {
  std::vector<std::int64_t> row;
  std::int64_t first = 0, count = 0, all = 0;
};
PetscRows petsc_rows(std::span<const std::int32_t> owner, std::span<const unsigned char> skip, int per_node);

// A square AIJ matrix over the ranks, `rows` of its `all` rows this rank's, each preallocated
// for in_block entries in this rank's columns and off_block in the others' (upper bounds:
// clipped to the columns there are). Collective.
Mat petsc_matrix(PetscInt rows, PetscInt all, std::vector<PetscInt> in_block, std::vector<PetscInt> off_block);

struct PetscObjects;
// The matrix in `o`, its values set, assembled; its vectors, the right-hand side this rank's
// rows (local_rhs); a solver of `type` on it. Returns the solver's preconditioner, for the
// caller to choose. Collective.
PC petsc_prepare(PetscObjects& o, std::span<const double> local_rhs, KSPType type);
// The matrix in `o` assembled again (its values set anew on its pattern) and the right-hand
// side this rank's rows: a kept solver's next solve. Collective.
void petsc_refill(PetscObjects& o, std::span<const double> local_rhs);
// Solves in `o` once PETSC_OPTIONS have had their say (options PETSc does not know are the
// user's input: InputError), and says what it came to: PETSc's reason and iterations, the
// method in words ("cg with hypre", "preonly with lu (mumps)"), and the true relative residual
// |b - A x| / |b| (whatever the options asked of the solver). A solve PETSc gives up (a
// factorisation that meets a zero pivot) leaves x zero, so that the residual says so. Collective.
// A solver's method in words ("cg with hypre", "preonly with lu (mumps)").
std::string petsc_method(KSP solver);
struct PetscOutcome {
  KSPConvergedReason reason = KSP_CONVERGED_ITERATING;
  int iterations = 0;
  std::string method;
  double relative = 0;
};
PetscOutcome petsc_solve(PetscObjects& o);
// o.x on every rank, handed to read(values) in the global rows' order. Collective.
void petsc_read_everywhere(PetscObjects& o, const std::function<void(const PetscScalar*)>& read);

// The PETSc objects of one solve, destroyed whatever happens.
struct PetscObjects {
  Mat matrix = nullptr;
  Vec x = nullptr, rhs = nullptr, everywhere = nullptr;
  VecScatter to_all = nullptr;
  KSP solver = nullptr;
  PetscObjects() = default;
  PetscObjects(const PetscObjects&) = delete;
  PetscObjects& operator=(const PetscObjects&) = delete;
  ~PetscObjects() {
    if (solver) KSPDestroy(&solver);
    if (to_all) VecScatterDestroy(&to_all);
    if (everywhere) VecDestroy(&everywhere);
    if (rhs) VecDestroy(&rhs);
    if (x) VecDestroy(&x);
    if (matrix) MatDestroy(&matrix);
  }
};

}  // namespace hemotree
