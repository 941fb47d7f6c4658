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

// A failure one rank meets alone would leave the others waiting in their next collective
// call. So steps that can fail run under one of these, which make a failure every rank's:
// the same kind of error (InputError, SettingError, IoError, std::bad_alloc; any other a
// std::runtime_error) with the same words, "rank K: " before them where rank K > 0 failed,
// thrown on every rank and marked collective. Collective; on one process, the step itself.
//   on_lead_rank: a step that only rank 0 takes (the output folder, the files).
//   on_every_rank: a step every rank takes (reading the network on its own node, setting up
//                  its share): the lowest failing rank's failure.
void on_lead_rank(const std::function<void()>& step);
void on_every_rank(const std::function<void()>& step);

// Whether the failure being handled was made every rank's (above, or by a distributed solve's
// own status: mark_collective_failure): then rank 0 alone says it and every rank ends alike;
// any other failure under several ranks is said by its rank and ends the run (MPI_Abort), so
// that no rank is left waiting (cli/tool.cpp).
void mark_collective_failure();
bool failure_is_collective();
// Ends the run on every rank with this exit status (MPI_Abort) where there are several;
// returns at once on one process.
void end_every_rank(int status);

}  // namespace hemotree
