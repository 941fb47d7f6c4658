#include "distributed/mpi_tree_system.hpp"

#include "mpi/session.hpp"

#include <algorithm>
#include <exception>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace hemotree {

MpiTreeSystem::MpiTreeSystem(MPI_Comm comm, const TreeCut& cut)
    : rank_(rank_in(comm)), share_(cut, rank_in(comm)), exchange_(comm, cut) {
  top_rank_ = cut.top_rank;
  share_size_ = share_.node_count();
  nodes_ = std::move(cut.held_nodes()[static_cast<std::size_t>(rank_)]);
  for (const std::int32_t r : cut.roots[static_cast<std::size_t>(rank_)])
    root_parents_.push_back(cut.parent[static_cast<std::size_t>(r)]);
  root_parent_potential_.assign(root_parents_.size(), 0.0);
  if (rank_ == top_rank_) top_.emplace_back(cut);
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
  // Move 1: this rank's share, its roots' numbers. Whatever fails here goes in the status,
  // never thrown before the collective calls the other ranks are in.
  std::exception_ptr failure;
  std::vector<double> message;
  const std::span<double> share_x = x.subspan(0, std::min(share_size_, x.size()));
  try {
    if (x.size() != nodes_.size() ||
        (factorizing && (conductance.size() != nodes_.size() || shunt.size() != nodes_.size())))
      throw std::invalid_argument("MpiTreeSystem: " + std::to_string(nodes_.size()) + " numbers of each kind on rank " +
                                  std::to_string(rank_));
    if (!factorizing && !factorized_)
      throw std::logic_error("MpiTreeSystem::solve: no factorisation succeeded on every rank");
    message = factorizing ? share_.factorize_forward(conductance.subspan(0, share_size_), shunt.subspan(0, share_size_), share_x)
                          : share_.forward(share_x);
  } catch (...) {
    failure = std::current_exception();
  }
  // Move 2, on the top's rank: the top solved; each root answered with its potential and its
  // parent's.
  const std::size_t own = rank_ == top_rank_ ? nodes_.size() - share_size_ : 0;
  std::vector<double> top_x(own);
  auto top_move = [&](std::span<const double> messages, std::span<double> answers) {
    std::vector<double> root_x(parent_of_slot_.size());
    const std::span<const double> b(x.data() + share_size_, own);
    if (factorizing) {
      const std::int64_t singular = top_[0].factorize_solve(conductance.subspan(share_size_), shunt.subspan(share_size_), b,
                                                            messages, top_x, root_x);
      if (singular >= 0) return static_cast<double>(singular);
    } else {
      top_[0].solve(b, messages, top_x, root_x);
    }
    for (std::size_t slot = 0; slot < root_x.size(); ++slot) {
      answers[2 * slot] = root_x[slot];
      const std::int32_t p = parent_of_slot_[slot];
      answers[2 * slot + 1] = p >= 0 ? top_x[static_cast<std::size_t>(p)] : 0.0;
    }
    return RootExchange::solved;
  };
  std::vector<double> got;
  try {
    got = exchange_.round(message, failure, stride, 2, top_move, "the distributed solve");
  } catch (...) {
    if (factorizing) factorized_ = false;
    throw;
  }
  // Move 3: this rank's share down from its roots' potentials.
  const double status = got[0];
  if (factorizing) factorized_ = status == RootExchange::solved;
  if (status >= 0) return static_cast<std::int64_t>(status);
  if (rank_ == top_rank_) std::copy(top_x.begin(), top_x.end(), x.begin() + static_cast<std::ptrdiff_t>(share_size_));
  std::vector<double> root_x(root_parents_.size());
  for (std::size_t k = 0; k < root_x.size(); ++k) {
    root_x[k] = got[1 + 2 * k];
    root_parent_potential_[k] = got[2 + 2 * k];
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
