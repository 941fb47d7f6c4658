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
  throw SingularHarmonicSystem(node, "harmonic system: node " + std::to_string(node) +
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

namespace {

// The edge from node i to its parent: the parent p, the entry in i's row and p's column
// (m_ip) and in p's row and i's column (m_pi).
struct ToParent {
  std::size_t p;
  Complex m_ip, m_pi;
};
template <class Edge>
ToParent to_parent(std::span<const std::int32_t> a, std::span<const std::int32_t> b, std::span<const Edge> y,
                         std::size_t i, std::int32_t edge) {
  const auto e = static_cast<std::size_t>(edge);
  const bool i_is_a = a[e] == static_cast<std::int32_t>(i);
  return {static_cast<std::size_t>(i_is_a ? b[e] : a[e]), i_is_a ? y[e].ab : y[e].ba, i_is_a ? y[e].ba : y[e].ab};
}

}  // namespace

template <class Edge>
void HarmonicSystem::sweep_up(std::span<const Edge> y, std::span<Complex> pivot, std::span<Complex> x) const {
  // Leaves up: node i, its pivot final, hands its parent p m_pi m_ip / d_i of the pivot and
  // m_pi B_i / d_i of the current (m_pi: the entry in p's row and i's column).
  for (std::size_t k = 0; k < nodes_; ++k) {
    const std::size_t i = eliminated(k);
    const std::int32_t e = parent_edge_[i];
    if (e < 0 && open_roots_) continue;  // d_r and y_r for the rest of the forest
    if (pivot[i] == Complex(0)) singular_at(i);
    if (e < 0) continue;
    const ToParent up = to_parent(std::span<const std::int32_t>(a_), std::span<const std::int32_t>(b_), y, i, e);
    pivot[i] = reciprocal(pivot[i]);  // kept as 1 / d_i for the way down
    const Complex m_pi_over_d = up.m_pi * pivot[i];
    pivot[up.p] -= m_pi_over_d * up.m_ip;
    x[up.p] -= m_pi_over_d * x[i];
  }
}

template <class Edge>
void HarmonicSystem::sweep_down(std::span<const Edge> y, std::span<const Complex> pivot, std::span<Complex> x) const {
  // Roots down: X_i = (B_i - m_ip X_p) / d_i; an open root's X_r is given.
  for (auto k = nodes_; k-- > 0;) {
    const std::size_t i = eliminated(k);
    const std::int32_t e = parent_edge_[i];
    if (e < 0) {
      if (!open_roots_) x[i] /= pivot[i];
      continue;
    }
    const ToParent up = to_parent(std::span<const std::int32_t>(a_), std::span<const std::int32_t>(b_), y, i, e);
    x[i] = (x[i] - up.m_ip * x[up.p]) * pivot[i];
  }
}

template <class Edge>
void HarmonicSystem::eliminate_forest(std::span<const Edge> y, std::span<Complex> pivot, std::span<Complex> x) const {
  if (open_roots_) throw std::logic_error("HarmonicSystem: a solve with open roots needs the rest of the forest");
  sweep_up(y, pivot, x);
  sweep_down(y, std::span<const Complex>(pivot), x);
}

void HarmonicSystem::solve_forest(std::span<const TwoPort> edge, std::span<Complex> pivot, std::span<Complex> x) const {
  const std::span<const std::int32_t> a = a_, b = b_;
  for (std::size_t e = 0; e < a.size(); ++e) {
    pivot[static_cast<std::size_t>(a[e])] += edge[e].aa;
    pivot[static_cast<std::size_t>(b[e])] += edge[e].bb;
  }
  eliminate_forest(edge, pivot, x);
}

void HarmonicSystem::check_forest_sizes(std::size_t couplings, std::size_t diagonal, std::size_t current) const {
  if (!forest_) throw std::logic_error("HarmonicSystem: the graph is not a forest");
  if (couplings != a_.size() || diagonal != nodes_ || current != nodes_)
    throw std::invalid_argument("harmonic system: one coupling per edge, one diagonal and current per node");
}

void HarmonicSystem::solve_forest_in_place(std::span<const Coupling> coupling, std::span<Complex> diagonal,
                                           std::span<Complex> current) const {
  check_forest_sizes(coupling.size(), diagonal.size(), current.size());
  eliminate_forest(coupling, diagonal, current);
}

void HarmonicSystem::eliminate_forest_up(std::span<const Coupling> coupling, std::span<Complex> diagonal,
                                         std::span<Complex> current) const {
  check_forest_sizes(coupling.size(), diagonal.size(), current.size());
  sweep_up(coupling, diagonal, current);
}

void HarmonicSystem::substitute_forest_down(std::span<const Coupling> coupling, std::span<const Complex> diagonal,
                                            std::span<Complex> current) const {
  check_forest_sizes(coupling.size(), diagonal.size(), current.size());
  sweep_down(coupling, diagonal, current);
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
