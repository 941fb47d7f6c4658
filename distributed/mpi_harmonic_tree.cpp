#include "distributed/mpi_harmonic_tree.hpp"

#include <exception>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace hemotree {

namespace {

// A complex number travels as its two doubles (std::complex<double> may be read as double[2];
// the way back is copied).
std::span<const double> as_doubles(std::span<const Complex> z) {
  return {reinterpret_cast<const double*>(z.data()), 2 * z.size()};
}
std::vector<Complex> as_complex(std::span<const double> d) {
  std::vector<Complex> z(d.size() / 2);
  for (std::size_t k = 0; k < z.size(); ++k) z[k] = {d[2 * k], d[2 * k + 1]};
  return z;
}

}  // namespace

MpiHarmonicTree::MpiHarmonicTree(MPI_Comm comm, const TreeCut& cut)
    : rank_(rank_in(comm)), share_(cut, rank_in(comm)), exchange_(comm, cut) {
  share_size_ = share_.node_count();
  nodes_ = std::move(cut.held_nodes()[static_cast<std::size_t>(rank_)]);
  for (const std::int32_t r : cut.roots[static_cast<std::size_t>(rank_)])
    root_parents_.push_back(cut.parent[static_cast<std::size_t>(r)]);
  root_parent_potential_.assign(root_parents_.size(), 0.0);
  if (!exchange_.top()) return;
  top_.emplace_back(cut);
  std::unordered_map<std::int32_t, std::int32_t> own;
  for (std::size_t i = share_size_; i < nodes_.size(); ++i) own.emplace(nodes_[i], static_cast<std::int32_t>(i - share_size_));
  for (const auto& roots : cut.roots)
    for (const std::int32_t r : roots) {
      parent_of_slot_.push_back(own.at(cut.parent[static_cast<std::size_t>(r)]));
      share_roots_.push_back(r);
    }
  share_root_potential_.assign(share_roots_.size(), 0.0);
}

void MpiHarmonicTree::solve(std::span<const Complex> shunt, std::span<const EdgeToParent> edge, std::span<Complex> x) {
  // Move 1: this rank's share up to its roots; a failure goes in the status.
  std::exception_ptr failure;
  std::vector<Complex> message;
  const std::size_t n = nodes_.size(), share = std::min(share_size_, x.size());
  try {
    if (shunt.size() != n || edge.size() != n || x.size() != n)
      throw std::invalid_argument("MpiHarmonicTree: " + std::to_string(n) + " numbers of each kind on rank " +
                                  std::to_string(rank_));
    message = share_.eliminate(shunt.first(share), edge.first(share), x.first(share));
  } catch (...) {
    failure = std::current_exception();
  }
  // Move 2 on the top's rank: the top solved, each root answered with its potential and its parent's.
  const std::size_t own = exchange_.top() ? n - share_size_ : 0;
  std::vector<Complex> top_x(own);
  auto top_move = [&](std::span<const double> messages, std::span<double> answers) {
    std::vector<Complex> root_x(parent_of_slot_.size());
    top_[0].solve(shunt.subspan(share_size_), x.subspan(share_size_), edge.subspan(share_size_), as_complex(messages), top_x,
                  root_x);
    std::copy(root_x.begin(), root_x.end(), share_root_potential_.begin());
    for (std::size_t slot = 0; slot < root_x.size(); ++slot) {
      const Complex p = top_x[static_cast<std::size_t>(parent_of_slot_[slot])];
      answers[4 * slot] = root_x[slot].real();
      answers[4 * slot + 1] = root_x[slot].imag();
      answers[4 * slot + 2] = p.real();
      answers[4 * slot + 3] = p.imag();
    }
    return RootExchange::solved;
  };
  const std::vector<double> got = exchange_.round(as_doubles(message), failure, 2 * HarmonicTreeShare::message_size, 4,
                                                  top_move, "the distributed harmonic solve");
  // Move 3: this rank's share down from its roots' potentials.
  if (exchange_.top()) std::copy(top_x.begin(), top_x.end(), x.begin() + static_cast<std::ptrdiff_t>(share_size_));
  const std::vector<Complex> answer = as_complex(std::span<const double>(got).subspan(1));
  std::vector<Complex> root_x(root_parents_.size());
  for (std::size_t k = 0; k < root_x.size(); ++k) {
    root_x[k] = answer[2 * k];
    root_parent_potential_[k] = answer[2 * k + 1];
  }
  share_.substitute(root_x, x.first(share_size_));
}

}  // namespace hemotree
