#include "network_flow/harmonic_system.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/Sparse>
#include <Eigen/SparseLU>

#include "network_flow/forest_order.hpp"

namespace hemotree {

namespace {

[[noreturn]] void singular_at(std::size_t node) {
  throw std::invalid_argument("harmonic system: node " + std::to_string(node) +
                              " lies in a part with no admittance to ground");
}

}  // namespace

HarmonicSystem::HarmonicSystem(std::size_t nodes, std::vector<std::int32_t> a, std::vector<std::int32_t> b)
    : nodes_(nodes), a_(std::move(a)), b_(std::move(b)) {
  if (b_.size() != a_.size()) throw std::invalid_argument("harmonic system: two nodes per edge");
  for (std::size_t e = 0; e < a_.size(); ++e)
    if (a_[e] < 0 || b_[e] < 0 || static_cast<std::size_t>(a_[e]) >= nodes || static_cast<std::size_t>(b_[e]) >= nodes ||
        a_[e] == b_[e])
      throw std::invalid_argument("harmonic system: edge " + std::to_string(e) + " joins no two distinct nodes");
  if (parents_below(nodes, a_, b_, parent_edge_)) {
    forest_ = true;  // order_ empty: the labels from the highest down
    return;
  }
  std::vector<std::int32_t> parent;
  forest_ = peel_leaves(nodes, a_, b_, order_, parent, parent_edge_);
  if (!forest_) order_ = {}, parent_edge_ = {};
}

std::vector<Complex> HarmonicSystem::solve(std::span<const TwoPort> edge, std::span<const Complex> shunt,
                                           std::span<const Complex> current) const {
  std::vector<Complex> pivot(shunt.begin(), shunt.end()), x(current.begin(), current.end());
  solve_in_place(edge, pivot, x);
  return x;
}

void HarmonicSystem::solve_in_place(std::span<const TwoPort> edge, std::span<Complex> shunt,
                                    std::span<Complex> current) const {
  if (edge.size() != a_.size() || shunt.size() != nodes_ || current.size() != nodes_)
    throw std::invalid_argument("harmonic system: one admittance per edge, one shunt and current per node");
  if (forest_) {
    solve_forest(edge, shunt, current);
  } else {
    solve_sparse(edge, shunt, current);
  }
}

template <class Edge>
void HarmonicSystem::eliminate_forest(std::span<const Edge> y, std::span<Complex> pivot, std::span<Complex> x) const {
  const std::span<const std::int32_t> a = a_, b = b_;
  // Leaves up: node i, its pivot final, hands its parent p m_pi m_ip / d_i of the pivot and
  // m_pi B_i / d_i of the current (m_pi: the entry in p's row and i's column).
  auto couplings = [&](std::size_t i, std::int32_t edge, std::size_t& p, Complex& m_ip, Complex& m_pi) {
    const auto e = static_cast<std::size_t>(edge);
    const bool i_is_a = a[e] == static_cast<std::int32_t>(i);
    p = static_cast<std::size_t>(i_is_a ? b[e] : a[e]);
    m_ip = i_is_a ? y[e].ab : y[e].ba;
    m_pi = i_is_a ? y[e].ba : y[e].ab;
  };
  for (std::size_t k = 0; k < nodes_; ++k) {
    const std::size_t i = eliminated(k);
    if (pivot[i] == Complex(0)) singular_at(i);
    const std::int32_t e = parent_edge_[i];
    if (e < 0) continue;
    std::size_t p;
    Complex m_ip, m_pi;
    couplings(i, e, p, m_ip, m_pi);
    pivot[i] = reciprocal(pivot[i]);  // kept as 1 / d_i for the way down
    const Complex m_pi_over_d = m_pi * pivot[i];
    pivot[p] -= m_pi_over_d * m_ip;
    x[p] -= m_pi_over_d * x[i];
  }
  // Roots down: X_i = (B_i - m_ip X_p) / d_i.
  for (auto k = nodes_; k-- > 0;) {
    const std::size_t i = eliminated(k);
    const std::int32_t e = parent_edge_[i];
    if (e < 0) {
      x[i] /= pivot[i];
      continue;
    }
    std::size_t p;
    Complex m_ip, m_pi;
    couplings(i, e, p, m_ip, m_pi);
    x[i] = (x[i] - m_ip * x[p]) * pivot[i];
  }
}

void HarmonicSystem::solve_forest(std::span<const TwoPort> edge, std::span<Complex> pivot, std::span<Complex> x) const {
  const std::span<const std::int32_t> a = a_, b = b_;
  for (std::size_t e = 0; e < a.size(); ++e) {
    pivot[static_cast<std::size_t>(a[e])] += edge[e].aa;
    pivot[static_cast<std::size_t>(b[e])] += edge[e].bb;
  }
  eliminate_forest(edge, pivot, x);
}

void HarmonicSystem::solve_forest_in_place(std::span<const Coupling> coupling, std::span<Complex> diagonal,
                                           std::span<Complex> current) const {
  if (!forest_) throw std::logic_error("HarmonicSystem::solve_forest_in_place: the graph is not a forest");
  if (coupling.size() != a_.size() || diagonal.size() != nodes_ || current.size() != nodes_)
    throw std::invalid_argument("harmonic system: one coupling per edge, one diagonal and current per node");
  eliminate_forest(coupling, diagonal, current);
}

// Loops: the assembled matrix and a sparse LU.
void HarmonicSystem::solve_sparse(std::span<const TwoPort> edge, std::span<const Complex> shunt,
                                  std::span<Complex> x) const {
  const std::size_t nodes = nodes_, edges = a_.size();
  std::vector<Eigen::Triplet<Complex>> entries;
  entries.reserve(nodes + 2 * edges);
  for (std::size_t i = 0; i < nodes; ++i)
    entries.emplace_back(static_cast<int>(i), static_cast<int>(i), shunt[i]);
  for (std::size_t e = 0; e < edges; ++e) {
    const int i = a_[e], j = b_[e];
    entries.emplace_back(i, i, edge[e].aa);
    entries.emplace_back(j, j, edge[e].bb);
    entries.emplace_back(i, j, edge[e].ab);
    entries.emplace_back(j, i, edge[e].ba);
  }
  Eigen::SparseMatrix<Complex> m(static_cast<Eigen::Index>(nodes), static_cast<Eigen::Index>(nodes));
  m.setFromTriplets(entries.begin(), entries.end());
  Eigen::SparseLU<Eigen::SparseMatrix<Complex>, Eigen::COLAMDOrdering<int>> lu;
  lu.compute(m);
  if (lu.info() != Eigen::Success)
    throw std::invalid_argument("harmonic system: singular (a part with no admittance to ground): " + lu.lastErrorMessage());
  const Eigen::Map<const Eigen::VectorXcd> rhs(x.data(), static_cast<Eigen::Index>(nodes));
  const Eigen::VectorXcd solution = lu.solve(rhs);
  for (Eigen::Index i = 0; i < solution.size(); ++i) {
    if (!std::isfinite(solution(i).real()) || !std::isfinite(solution(i).imag())) singular_at(static_cast<std::size_t>(i));
    x[static_cast<std::size_t>(i)] = solution(i);
  }
}

std::vector<Complex> solve_harmonic_system(std::size_t nodes, std::span<const std::int32_t> a,
                                           std::span<const std::int32_t> b, std::span<const TwoPort> edge,
                                           std::span<const Complex> shunt, std::span<const Complex> current) {
  if (b.size() != a.size()) throw std::invalid_argument("harmonic system: two nodes per edge");
  return HarmonicSystem(nodes, {a.begin(), a.end()}, {b.begin(), b.end()}).solve(edge, shunt, current);
}

}  // namespace hemotree
