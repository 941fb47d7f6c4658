// MPI for a tool started by a launcher on several ranks (cli/tool.cpp): initialised once
// (threads funneled: OpenMP within a rank, MPI from its main thread) and finalised when the
// session ends. A tool started as a plain command, or on one rank, never initialises it and
// stays one process: world_size() 1, world_rank() 0.
#pragma once

#include <functional>

#include <mpi.h>

namespace hemotree {

class MpiSession {
 public:
  MpiSession(int& argc, char**& argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
};

int world_size();
int world_rank();

// Called when the session ends, before MPI is finalised, the last registered first: a library
// started on MPI (PETSc) finalised before it.
void at_session_end(std::function<void()> step);

// Runs a step that only rank 0 takes (the output folder, the files) and makes its failure
// every rank's: the same kind of error (InputError, SettingError, IoError; any other a
// std::runtime_error) with the same message on each, so that no rank waits in a collective
// for one that has left. Collective; on one process, the step itself.
void on_lead_rank(const std::function<void()>& step);

}  // namespace hemotree
