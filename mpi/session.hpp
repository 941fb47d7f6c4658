// MPI for a tool started by a launcher on several ranks (cli/tool.cpp): initialised once
// (threads funneled: OpenMP within a rank, MPI from its main thread) and finalised when the
// session ends. The threads MPI starts for itself never take SIGINT, SIGTERM or SIGHUP: the
// run's main thread answers them (cli/interrupt.hpp). A tool started as a plain command, or on one rank, never initialises it and
// stays one process: world_size() 1, world_rank() 0.
#pragma once

#include <functional>
#include <string>

#include <mpi.h>

namespace hemotree {

class MpiSession {
 public:
  MpiSession(int& argc, char**& argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
};

// MPI_COMM_WORLD's where MPI is in use (a session's, or initialised by a program that calls
// these libraries), else 1 and 0.
int world_size();
int world_rank();

// Called when the session ends, before MPI is finalised, the last registered first: a library
// started on MPI (PETSc) finalised before it.
void at_session_end(std::function<void()> step);

// A failure every rank meets alike, thrown on every rank: run_tool says it once, by rank 0,
// and every rank ends with its status. Any other failure under several ranks is one rank's
// own: said by that rank and ending the run on every rank (end_every_rank), so that no rank
// is left waiting in a collective call for one that has left (cli/tool.cpp).
struct CollectiveFailure {
  virtual ~CollectiveFailure() = default;
};
template <class Error>
struct Collective : Error, CollectiveFailure {
  using Error::Error;
};

// A failure one rank meets alone would leave the others waiting in their next collective
// call. So steps that can fail run under one of these, which make a failure every rank's:
// the same kind of error (InputError, SettingError, JsonError, IoError; running out of
// memory an IoError "out of memory"; any other a std::runtime_error) with the same words,
// "rank K: " before them where rank K > 0 failed, thrown on every rank as Collective<kind>.
// Collective; on one process, the step itself.
//   on_lead_rank: a step that only rank 0 takes (the output folder, the files).
//   on_every_rank: a step every rank takes (reading the network on its own node, setting up
//                  its share): the lowest failing rank's failure.
void on_lead_rank(const std::function<void()>& step);
void on_every_rank(const std::function<void()>& step);
// The words of rank `from`'s failure on every rank (its `words` there; "" elsewhere in).
// Collective: every rank must know `from`.
std::string words_of(int from, std::string words);

// Rank 0's answer on every rank (where a rank's own view could differ: a file on its node).
// Collective.
bool lead_answer(bool answer);

// Said by the rank that has left every collective call for good (rank 0 writing the results
// after the last gather): its failures are then its own alone, said plainly, and end no other
// rank (they have finished).
void leave_collectives();
bool left_collectives();

// Ends the run on every rank with this exit status (MPI_Abort) where there are several;
// returns at once on one process.
void end_every_rank(int status);

}  // namespace hemotree
