// PETSc on the MPI session, for the solvers that use it (petsc_flow_network,
// petsc_harmonic_network): started once, finalised before MPI when the session ends, its
// error codes as exceptions (its own printing of a traceback turned off), and the objects of
// a solve.
#pragma once

#include <petscksp.h>

namespace hemotree {

void start_petsc();
// Throws std::runtime_error "PETSc: WHAT failed: its message" for a non-zero code.
void petsc_check(PetscErrorCode code, const char* what);
// PETSC_OPTIONS given to a solver (KSPSetFromOptions' code): InputError where it refuses them.
void petsc_options_check(PetscErrorCode code);

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
