#include "distributed/mpi_tree_system.hpp"

#include "mpi/session.hpp"

#include <algorithm>
#include <exception>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace hemotree {

namespace {

// A reply's first number: all went well, or a rank refused its numbers (-2 - rank), or the
// forest is singular (the node naming it, >= 0).
constexpr double solved = -1;
double refused_by(int rank) { return -2.0 - rank; }

int rank_in(MPI_Comm comm) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  return rank;
}

}  // namespace

MpiTreeSystem::MpiTreeSystem(MPI_Comm comm, const TreeCut& cut)
    : comm_(comm), rank_(rank_in(comm)), share_(cut, rank_in(comm)) {
  int size = 0;
  MPI_Comm_size(comm_, &size);
  if (size != cut.ranks)
    throw std::invalid_argument("MpiTreeSystem: a cut for " + std::to_string(cut.ranks) + " ranks on " +
                                std::to_string(size));
  top_rank_ = cut.top_rank;
  share_size_ = share_.node_count();
  nodes_ = std::move(cut.held_nodes()[static_cast<std::size_t>(rank_)]);
  for (const std::int32_t r : cut.roots[static_cast<std::size_t>(rank_)])
    root_parents_.push_back(cut.parent[static_cast<std::size_t>(r)]);
  root_parent_potential_.assign(root_parents_.size(), 0.0);
  if (rank_ == top_rank_) top_.emplace_back(cut);
  for (int r = 0; r < cut.ranks; ++r) {
    const int roots = static_cast<int>(cut.roots[static_cast<std::size_t>(r)].size());
    message_count_.push_back(1 + roots);  // for a solve; a factorisation sends 1 + 3 roots
    answer_count_.push_back(1 + 2 * roots);
  }
  answer_offset_.assign(answer_count_.size(), 0);
  for (std::size_t r = 1; r < answer_count_.size(); ++r) answer_offset_[r] = answer_offset_[r - 1] + answer_count_[r - 1];
  // The top's rank finds each root's parent among the top's own nodes, for its answer.
  if (rank_ == top_rank_) {
    const std::span<const std::int32_t> top(nodes_.data() + share_size_, nodes_.size() - share_size_);
    std::unordered_map<std::int32_t, std::int32_t> own;
    for (std::size_t i = 0; i < top.size(); ++i) own.emplace(top[i], static_cast<std::int32_t>(i));
    for (const auto& roots : cut.roots)
      for (const std::int32_t r : roots) {
        const std::int32_t p = cut.parent[static_cast<std::size_t>(r)];
        parent_of_slot_.push_back(p >= 0 ? own.at(p) : -1);
      }
  }
}

std::int64_t MpiTreeSystem::exchange(std::span<const double> conductance, std::span<const double> shunt,
                                     std::span<double> x, bool factorizing) {
  const std::size_t stride = factorizing ? 3 : 1;
  // Move 1: this rank's share, its roots' numbers behind a status. Whatever fails here is
  // said in the status, never thrown before the collective calls the other ranks are in.
  std::exception_ptr failure;
  std::vector<double> message{0.0};
  const std::span<double> share_x = x.subspan(0, std::min(share_size_, x.size()));
  try {
    if (x.size() != nodes_.size() ||
        (factorizing && (conductance.size() != nodes_.size() || shunt.size() != nodes_.size())))
      throw std::invalid_argument("MpiTreeSystem: " + std::to_string(nodes_.size()) + " numbers of each kind on rank " +
                                  std::to_string(rank_));
    if (!factorizing && !factorized_)
      throw std::logic_error("MpiTreeSystem::solve: no factorisation succeeded on every rank");
    const std::vector<double> roots = factorizing
                                          ? share_.factorize_forward(conductance.subspan(0, share_size_),
                                                                     shunt.subspan(0, share_size_), share_x)
                                          : share_.forward(share_x);
    message.insert(message.end(), roots.begin(), roots.end());
  } catch (...) {
    failure = std::current_exception();
    message.assign(1 + stride * root_parents_.size(), 0.0);
    message[0] = 1;
  }
  const bool top = rank_ == top_rank_;
  std::vector<int> counts(message_count_.size()), offsets(message_count_.size(), 0);
  for (std::size_t r = 0; r < counts.size(); ++r) {
    counts[r] = 1 + static_cast<int>(stride) * (message_count_[r] - 1);
    if (r > 0) offsets[r] = offsets[r - 1] + counts[r - 1];
  }
  std::vector<double> gathered(top ? static_cast<std::size_t>(offsets.back() + counts.back()) : 0);
  double entered = MPI_Wtime();
  MPI_Gatherv(message.data(), static_cast<int>(message.size()), MPI_DOUBLE, gathered.data(), counts.data(),
              offsets.data(), MPI_DOUBLE, top_rank_, comm_);
  traffic_.seconds += MPI_Wtime() - entered;
  traffic_.calls += 1;
  traffic_.bytes += sizeof(double) * (message.size() + gathered.size());

  // Move 2, on the top's rank: the top solved, or the first refusal or the singular node said.
  std::vector<double> answers;
  if (top) {
    answers.assign(static_cast<std::size_t>(answer_offset_.back() + answer_count_.back()), 0.0);
    double status = solved;
    std::vector<double> messages;
    for (std::size_t r = 0; r < counts.size() && status == solved; ++r) {
      const double* m = gathered.data() + offsets[r];
      if (m[0] != 0) status = refused_by(static_cast<int>(r));
      messages.insert(messages.end(), m + 1, m + counts[r]);
    }
    const std::size_t own = nodes_.size() - share_size_;
    std::vector<double> top_x(own), root_x(parent_of_slot_.size());
    if (status == solved) {
      try {
        const std::span<const double> b(x.data() + share_size_, own);
        if (factorizing) {
          const std::int64_t singular = top_[0].factorize_solve(conductance.subspan(share_size_), shunt.subspan(share_size_),
                                                                b, messages, top_x, root_x);
          if (singular >= 0) status = static_cast<double>(singular);
        } else {
          top_[0].solve(b, messages, top_x, root_x);
        }
      } catch (...) {
        if (!failure) failure = std::current_exception();
        status = refused_by(rank_);
      }
    }
    if (status == solved) std::copy(top_x.begin(), top_x.end(), x.begin() + static_cast<std::ptrdiff_t>(share_size_));
    std::size_t slot = 0;
    for (std::size_t r = 0; r < answer_count_.size(); ++r) {
      double* a = answers.data() + answer_offset_[r];
      a[0] = status;
      if (status != solved) {
        slot += static_cast<std::size_t>(answer_count_[r] - 1) / 2;
        continue;
      }
      for (int k = 0; k < (answer_count_[r] - 1) / 2; ++k, ++slot) {
        a[1 + 2 * k] = root_x[slot];
        const std::int32_t p = parent_of_slot_[slot];
        a[2 + 2 * k] = p >= 0 ? top_x[static_cast<std::size_t>(p)] : 0.0;
      }
    }
  }
  std::vector<double> answer(static_cast<std::size_t>(answer_count_[static_cast<std::size_t>(rank_)]));
  entered = MPI_Wtime();
  MPI_Scatterv(answers.data(), answer_count_.data(), answer_offset_.data(), MPI_DOUBLE, answer.data(),
               static_cast<int>(answer.size()), MPI_DOUBLE, top_rank_, comm_);
  traffic_.seconds += MPI_Wtime() - entered;
  traffic_.calls += 1;
  traffic_.bytes += sizeof(double) * (answers.size() + answer.size());

  // Move 3: this rank's share down from its roots' potentials. A failure is every rank's.
  const double status = answer[0];
  if (factorizing) factorized_ = status == solved;
  if (status <= -2) {
    // The refusing rank's own words, on every rank.
    const int refusing = static_cast<int>(-2 - status);
    std::string words;
    if (refusing == rank_ && failure) {
      try {
        std::rethrow_exception(failure);
      } catch (const std::exception& e) {
        words = e.what();
      } catch (...) {
        words = "a failure";
      }
    }
    throw Collective<std::invalid_argument>("the distributed solve: " + words_of(refusing, words));
  }
  if (status >= 0) return static_cast<std::int64_t>(status);
  std::vector<double> root_x(root_parents_.size());
  for (std::size_t k = 0; k < root_x.size(); ++k) {
    root_x[k] = answer[1 + 2 * k];
    root_parent_potential_[k] = answer[2 + 2 * k];
  }
  share_.backward(root_x, share_x);
  return -1;
}

std::int64_t MpiTreeSystem::factorize_solve(std::span<const double> conductance, std::span<const double> shunt,
                                            std::span<double> x) {
  return exchange(conductance, shunt, x, true);
}

void MpiTreeSystem::solve(std::span<double> x) { exchange({}, {}, x, false); }

}  // namespace hemotree
