#include "distributed/petsc_session.hpp"

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

}  // namespace hemotree
