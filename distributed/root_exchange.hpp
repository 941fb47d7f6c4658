// The messages of a cut tree's distributed solve (distributed/tree_share.hpp's three moves)
// over MPI: every rank's numbers for the top, a few per share root, gathered to the top's
// rank in rank order behind a status (one MPI_Gatherv), and the top's answers scattered back
// behind one (one MPI_Scatterv). A rank that fails in its move says so in its status instead
// of leaving the collective calls the others are in; the top's rank answers every rank with
// the first refusal, and every rank throws that rank's words alike.
#pragma once

#include <cstdint>
#include <exception>
#include <functional>
#include <span>
#include <vector>

#include <mpi.h>

#include "distributed/tree_share.hpp"

namespace hemotree {

// This process's rank in comm.
int rank_in(MPI_Comm comm);

class RootExchange {
 public:
  // roots: per rank of comm (MPI_COMM_WORLD or a copy of it), its share roots (TreeCut::roots'
  // sizes). No communication.
  RootExchange(MPI_Comm comm, int top_rank, std::vector<int> roots);
  // The same for a cut tree's shares and top (TreeCut::roots, TreeCut::top_rank).
  RootExchange(MPI_Comm comm, const TreeCut& cut);
  int rank() const { return rank_; }
  bool top() const { return rank_ == top_rank_; }

  // An answer's status: solved, or (>= 0) a node the top's solve names (a singular forest).
  static constexpr double solved = -1;

  // The top's move: every rank's message (`send` numbers per root, rank after rank) in; the
  // answers (`back` numbers per root, rank after rank) out; returns solved or a node >= 0.
  using TopMove = std::function<double(std::span<const double> messages, std::span<double> answers)>;

  // One round, collective. message: this rank's `send` numbers per root, or `failure` set
  // where its move failed (its words, said by every rank). top_move runs on the top's rank
  // only, once every message came without failure; what it throws is the top's refusal.
  // Returns this rank's answer: the status, then `back` numbers per root. A refusal is thrown
  // on every rank: mpi/session.hpp's Collective<std::invalid_argument>, `what` and the
  // refusing rank's words ("rank K: " before them where K > 0).
  std::vector<double> round(std::span<const double> message, std::exception_ptr failure, std::size_t send,
                            std::size_t back, const TopMove& top_move, const char* what);

  // A round in its two halves, for a caller whose top move runs between them with work of its
  // own (a pulsatile step: the top's 1D vessels between the 0D step's halves). gather: this
  // rank's `send` numbers per root, or its failure; on the top's rank returns every rank's,
  // rank after rank, and sets `failed` where some rank failed (the top then scatters at once);
  // elsewhere nothing. scatter: on the top's rank the answers (`back` numbers per root, rank
  // after rank), or on any rank its failure (every rank passes the one it gathered with);
  // returns this rank's numbers, or throws the first refusal (the gather's, else the top's)
  // on every rank alike, as round() does. Every rank calls both, in turn.
  std::vector<double> gather(std::span<const double> message, std::exception_ptr failure, std::size_t send,
                             bool& failed);
  std::vector<double> scatter(std::span<const double> answers, std::exception_ptr failure, std::size_t back,
                              const char* what);

  // What this rank's rounds have cost so far: the collective calls (two a round), the bytes
  // sent and received in them, and the seconds inside them (waiting for the slowest rank
  // included).
  struct Traffic {
    int calls = 0;
    std::size_t bytes = 0;
    double seconds = 0;
  };
  const Traffic& traffic() const { return traffic_; }

 private:
  MPI_Comm comm_;
  int rank_ = 0, top_rank_ = 0;
  std::vector<int> roots_;
  Traffic traffic_;
  double refusal_ = -1;  // the top's, between the halves: solved, the gather's first refusal, or a node named
  // scatter's answer with its status first (what round() returns).
  std::vector<double> scatter_with_status(std::span<const double> answers, std::exception_ptr failure,
                                          std::size_t back, const char* what);
};

}  // namespace hemotree
