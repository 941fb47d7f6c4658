#include "distributed/root_exchange.hpp"

#include <stdexcept>
#include <string>

#include "mpi/session.hpp"

namespace hemotree {

namespace {

// A status in an answer below solved: rank K refused (-2 - K).
double refused_by(int rank) { return -2.0 - rank; }

std::string words(const std::exception_ptr& failure) {
  try {
    std::rethrow_exception(failure);
  } catch (const std::exception& e) {
    return e.what();
  } catch (...) {
    return "a failure";
  }
}

std::vector<int> root_counts(const TreeCut& cut) {
  std::vector<int> out;
  for (const auto& roots : cut.roots) out.push_back(static_cast<int>(roots.size()));
  return out;
}

}  // namespace

int rank_in(MPI_Comm comm) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  return rank;
}

RootExchange::RootExchange(MPI_Comm comm, const TreeCut& cut) : RootExchange(comm, cut.top_rank, root_counts(cut)) {}

RootExchange::RootExchange(MPI_Comm comm, int top_rank, std::vector<int> roots)
    : comm_(comm), rank_(rank_in(comm)), top_rank_(top_rank), roots_(std::move(roots)) {
  // A refusal's words travel over MPI_COMM_WORLD (mpi/session.hpp's words_of).
  int same = MPI_UNEQUAL;
  MPI_Comm_compare(comm_, MPI_COMM_WORLD, &same);
  if (same != MPI_IDENT && same != MPI_CONGRUENT)
    throw std::invalid_argument("RootExchange: a communicator of MPI_COMM_WORLD's ranks, in its order");
  int size = 0;
  MPI_Comm_size(comm_, &size);
  if (static_cast<std::size_t>(size) != roots_.size() || top_rank < 0 || top_rank >= size)
    throw std::invalid_argument("RootExchange: roots for " + std::to_string(roots_.size()) + " ranks, the top on rank " +
                                std::to_string(top_rank) + ", on " + std::to_string(size));
}

std::vector<double> RootExchange::round(std::span<const double> message, std::exception_ptr failure, std::size_t send,
                                        std::size_t back, const TopMove& top_move, const char* what) {
  bool failed = false;
  const std::vector<double> messages = gather(message, failure, send, failed);
  std::vector<double> answers;
  if (top() && !failed) {
    // The top's move: every root's answer, or what it throws as the top's refusal.
    std::size_t roots = 0;
    for (const int r : roots_) roots += static_cast<std::size_t>(r);
    answers.assign(back * roots, 0.0);
    try {
      const double status = top_move(messages, answers);
      if (status != solved) refusal_ = status;  // a node the top names (>= 0)
    } catch (...) {
      if (!failure) failure = std::current_exception();
    }
  }
  return scatter_with_status(answers, failure, back, what);
}

std::vector<double> RootExchange::gather(std::span<const double> message, std::exception_ptr failure, std::size_t send,
                                         bool& failed) {
  const auto mine = static_cast<std::size_t>(roots_[static_cast<std::size_t>(rank_)]);
  std::vector<double> sent(1 + send * mine, 0.0);
  if (!failure && message.size() != send * mine)
    failure = std::make_exception_ptr(std::invalid_argument("RootExchange: " + std::to_string(send * mine) +
                                                            " numbers expected from rank " + std::to_string(rank_)));
  if (failure)
    sent[0] = 1;
  else
    std::copy(message.begin(), message.end(), sent.begin() + 1);
  const std::size_t ranks = roots_.size();
  std::vector<int> counts(ranks), offsets(ranks, 0);
  for (std::size_t r = 0; r < ranks; ++r) {
    counts[r] = 1 + static_cast<int>(send) * roots_[r];
    if (r > 0) offsets[r] = offsets[r - 1] + counts[r - 1];
  }
  std::vector<double> gathered(top() ? static_cast<std::size_t>(offsets.back() + counts.back()) : 0);
  const double entered = MPI_Wtime();
  MPI_Gatherv(sent.data(), static_cast<int>(sent.size()), MPI_DOUBLE, gathered.data(), counts.data(), offsets.data(),
              MPI_DOUBLE, top_rank_, comm_);
  traffic_.seconds += MPI_Wtime() - entered;
  traffic_.calls += 1;
  traffic_.bytes += sizeof(double) * (sent.size() + gathered.size());
  failed = false;
  refusal_ = solved;
  std::vector<double> messages;
  if (!top()) return messages;
  for (std::size_t r = 0; r < ranks && !failed; ++r) {
    const double* m = gathered.data() + offsets[r];
    if (m[0] != 0) {
      refusal_ = refused_by(static_cast<int>(r));
      failed = true;
    }
    messages.insert(messages.end(), m + 1, m + counts[r]);
  }
  if (failed) messages.clear();
  return messages;
}

std::vector<double> RootExchange::scatter(std::span<const double> answers, std::exception_ptr failure, std::size_t back,
                                          const char* what) {
  std::vector<double> answer = scatter_with_status(answers, failure, back, what);
  answer.erase(answer.begin());
  return answer;
}

std::vector<double> RootExchange::scatter_with_status(std::span<const double> answers, std::exception_ptr failure,
                                                      std::size_t back, const char* what) {
  const std::size_t ranks = roots_.size();
  std::vector<int> answer_counts(ranks), answer_offsets(ranks, 0);
  for (std::size_t r = 0; r < ranks; ++r) {
    answer_counts[r] = 1 + static_cast<int>(back) * roots_[r];
    if (r > 0) answer_offsets[r] = answer_offsets[r - 1] + answer_counts[r - 1];
  }
  // The top's status: the gather's first refusal, else its own failure, else solved (or a
  // node its move named).
  std::vector<double> all;
  if (top()) {
    double status = refusal_;
    if (status == solved && failure) status = refused_by(rank_);
    const std::size_t expected = static_cast<std::size_t>(answer_offsets.back() + answer_counts.back()) - ranks;
    if (status == solved && answers.size() != expected) {
      failure = std::make_exception_ptr(std::invalid_argument("RootExchange: " + std::to_string(expected) +
                                                              " answers expected from the top"));
      status = refused_by(rank_);
    }
    all.assign(static_cast<std::size_t>(answer_offsets.back() + answer_counts.back()), 0.0);
    std::size_t from = 0;
    for (std::size_t r = 0; r < ranks; ++r) {
      double* a = all.data() + answer_offsets[r];
      a[0] = status;
      const auto count = static_cast<std::size_t>(answer_counts[r] - 1);
      if (status == solved) std::copy(answers.begin() + static_cast<std::ptrdiff_t>(from),
                                      answers.begin() + static_cast<std::ptrdiff_t>(from + count), a + 1);
      from += count;
    }
  }
  std::vector<double> answer(static_cast<std::size_t>(answer_counts[static_cast<std::size_t>(rank_)]));
  const double entered = MPI_Wtime();
  MPI_Scatterv(all.data(), answer_counts.data(), answer_offsets.data(), MPI_DOUBLE, answer.data(),
               static_cast<int>(answer.size()), MPI_DOUBLE, top_rank_, comm_);
  traffic_.seconds += MPI_Wtime() - entered;
  traffic_.calls += 1;
  traffic_.bytes += sizeof(double) * (all.size() + answer.size());
  if (const double status = answer[0]; status <= -2) {
    const int refusing = static_cast<int>(-2 - status);
    throw Collective<std::invalid_argument>(std::string(what) + ": " +
                                            words_of(refusing, refusing == rank_ && failure ? words(failure) : ""));
  }
  return answer;
}

}  // namespace hemotree
