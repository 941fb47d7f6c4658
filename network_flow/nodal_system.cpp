#include "network_flow/nodal_system.hpp"

#include <algorithm>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

#include <Eigen/SparseCholesky>

#include "network_flow/forest_order.hpp"

namespace hemotree {

// A Cholesky pivot this small against its row's unreduced diagonal is a nearly singular
// component (a shunt lost in rounding against the conductances): the subtractions of the
// factorisation leave the solution no correct digit. (The tree elimination does not subtract,
// and solves such a system exactly to rounding.)
static constexpr double singular_pivot = 1e-13;

// The lower triangle of the weighted Laplacian in compressed columns, its analysed
// factorisation, and where each edge's and node's value sits in it (so that a refactorisation
// overwrites the values in place: O(nonzeros), no triplets).
struct NodalSystem::Cholesky {
  // Eigen's LDL^T with its pivots D read in place: vectorD() returns a copy, O(nodes) at every
  // call, which inverse_diagonal's few short paths up the elimination tree would not amortise.
  struct Ldlt : Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower> {
    const Eigen::VectorXd& pivots() const { return this->m_diag; }
  };
  Eigen::SparseMatrix<double> lower;
  Ldlt ldlt;
  std::vector<Eigen::Index> edge_slot, diagonal_slot;
};

namespace {

std::int32_t find_root(std::vector<std::int32_t>& up, std::int32_t i) {
  while (up[static_cast<std::size_t>(i)] != i) {
    auto& next = up[static_cast<std::size_t>(i)];
    next = up[static_cast<std::size_t>(next)];  // path halving
    i = next;
  }
  return i;
}

}  // namespace

NodalSystem::NodalSystem(std::size_t nodes, std::vector<std::int32_t> a, std::vector<std::int32_t> b,
                         Method method)
    : nodes_(nodes), edges_(a.size()), a_(std::move(a)), b_(std::move(b)) {
  if (nodes_ > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    throw std::invalid_argument("NodalSystem: " + std::to_string(nodes_) + " nodes exceed 32-bit indices");
  if (a_.size() != b_.size())
    throw std::invalid_argument("NodalSystem: " + std::to_string(a_.size()) + " edge starts but " +
                                std::to_string(b_.size()) + " edge ends");
  const auto n = static_cast<std::int32_t>(nodes_);
  const std::size_t m = a_.size();
  for (std::size_t e = 0; e < m; ++e) {
    if (a_[e] < 0 || a_[e] >= n || b_[e] < 0 || b_[e] >= n)
      throw std::invalid_argument("NodalSystem: edge " + std::to_string(e) + " joins nodes " +
                                  std::to_string(a_[e]) + " and " + std::to_string(b_[e]) + ", not both below " +
                                  std::to_string(nodes_));
    if (a_[e] == b_[e])
      throw std::invalid_argument("NodalSystem: edge " + std::to_string(e) + " joins node " +
                                  std::to_string(a_[e]) + " to itself");
  }

  if (m > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    throw std::invalid_argument("NodalSystem: " + std::to_string(m) + " edges exceed 32-bit indices");

  // Is the graph a forest, and in what order can it be eliminated (every parent before its
  // children)? First the common case at the cost of one pass (forest_order.hpp): the nodes'
  // own order serves.
  bool forest = false;
  if (method != Method::sparse_cholesky) {
    forest = parents_below(nodes_, a_, b_, parent_edge_);
    parent_.assign(nodes_, -1);
    if (forest) {
      for (std::size_t c = 0; c < nodes_; ++c)
        if (const std::int32_t e = parent_edge_[c]; e >= 0)
          parent_[c] = std::min(a_[static_cast<std::size_t>(e)], b_[static_cast<std::size_t>(e)]);
    } else {
      forest = peel_leaves(nodes_, a_, b_, order_, parent_, parent_edge_);
      std::reverse(order_.begin(), order_.end());  // roots first
    }
  }
  if (method == Method::tree_elimination && !forest)
    throw std::invalid_argument("NodalSystem: tree_elimination needs a forest, and this graph has a loop or "
                                "a doubled edge");
  method_ = method == Method::automatic ? (forest ? Method::tree_elimination : Method::sparse_cholesky) : method;

  if (method_ == Method::tree_elimination) {
    // Edges numbered by the nodes they lead to (node c's edge to its parent is c - 1: a tree's
    // vessels in the order of their distal nodes, as the 0D vessels' are) need no list.
    bool edge_before = true;
    for (std::size_t c = 0; c < nodes_ && edge_before; ++c)
      edge_before = parent_[c] < 0 || static_cast<std::size_t>(parent_edge_[c]) + 1 == c;
    if (edge_before) std::vector<std::int32_t>().swap(parent_edge_);
    inverse_pivot_.assign(nodes_, 0.0);
    divider_.assign(nodes_, 0.0);
    plan_subtrees();
    std::vector<std::int32_t>().swap(a_);
    std::vector<std::int32_t>().swap(b_);
  } else {
    order_ = {};
    parent_ = {};
    parent_edge_ = {};
    // Each component is named by its lowest node: union-find that keeps the lower root at
    // every union ends with it as the root.
    std::vector<std::int32_t> up(nodes_);
    std::iota(up.begin(), up.end(), 0);
    for (std::size_t e = 0; e < m; ++e) {
      const std::int32_t ra = find_root(up, a_[e]), rb = find_root(up, b_[e]);
      up[static_cast<std::size_t>(std::max(ra, rb))] = std::min(ra, rb);
    }
    component_.resize(nodes_);
    for (std::int32_t i = 0; i < n; ++i) component_[static_cast<std::size_t>(i)] = find_root(up, i);
    grounded_.resize(nodes_);

    // The pattern: every edge's off-diagonal entry (doubled edges share one) and the whole
    // diagonal, analysed once (AMD ordering, elimination tree, column counts).
    cholesky_ = std::make_unique<Cholesky>();
    Cholesky& c = *cholesky_;
    std::vector<Eigen::Triplet<double, int>> pattern;
    pattern.reserve(nodes_ + m);
    for (std::int32_t i = 0; i < n; ++i) pattern.emplace_back(i, i, 1.0);
    for (std::size_t e = 0; e < m; ++e) pattern.emplace_back(std::max(a_[e], b_[e]), std::min(a_[e], b_[e]), 1.0);
    c.lower.resize(n, n);
    c.lower.setFromTriplets(pattern.begin(), pattern.end());
    c.lower.makeCompressed();
    const int* outer = c.lower.outerIndexPtr();
    const int* inner = c.lower.innerIndexPtr();
    auto slot = [&](std::int32_t row, std::int32_t col) {
      const int* first = inner + outer[col];
      const int* last = inner + outer[col + 1];
      return static_cast<Eigen::Index>(std::lower_bound(first, last, row) - inner);
    };
    c.diagonal_slot.resize(nodes_);
    for (std::int32_t i = 0; i < n; ++i) c.diagonal_slot[static_cast<std::size_t>(i)] = slot(i, i);
    c.edge_slot.resize(m);
    for (std::size_t e = 0; e < m; ++e) c.edge_slot[e] = slot(std::max(a_[e], b_[e]), std::min(a_[e], b_[e]));
    if (nodes_ > 0) c.ldlt.analyzePattern(c.lower);
  }
}

// No nodes: an empty forest, solved by the elimination (nothing to eliminate).
NodalSystem::NodalSystem() : method_(Method::tree_elimination) {}
NodalSystem::~NodalSystem() = default;
NodalSystem::NodalSystem(NodalSystem&&) noexcept = default;
NodalSystem& NodalSystem::operator=(NodalSystem&&) noexcept = default;

std::int64_t NodalSystem::factorize(std::span<const double> conductance, std::span<const double> shunt) {
  return factorize(conductance, shunt, nullptr);
}

std::int64_t NodalSystem::factorize_forward(std::span<const double> conductance, std::span<const double> shunt,
                                            std::span<double> y) {
  if (y.size() != nodes_)
    throw std::invalid_argument("NodalSystem::factorize_forward: right-hand side of " + std::to_string(y.size()) +
                                " for " + std::to_string(nodes_) + " nodes");
  return factorize(conductance, shunt, y.data());
}

void NodalSystem::allocate_pivots() {
  if (inverse_pivot_.size() == nodes_) return;  // else released (or never made)
  inverse_pivot_.assign(nodes_, 0.0);
  divider_.assign(nodes_, 0.0);
}

std::span<double> NodalSystem::shunt_workspace() {
  if (method_ != Method::tree_elimination) {
    shunt_workspace_.resize(nodes_);
    return shunt_workspace_;
  }
  allocate_pivots();
  return inverse_pivot_;
}

std::int64_t NodalSystem::factorize_in_place(std::span<const double> conductance) {
  return factorize_forward_in_place(conductance, {});
}

std::int64_t NodalSystem::factorize_forward_in_place(std::span<const double> conductance, std::span<double> y) {
  if (y.data() && y.size() != nodes_)
    throw std::invalid_argument("NodalSystem::factorize_forward_in_place: right-hand side of " +
                                std::to_string(y.size()) + " for " + std::to_string(nodes_) + " nodes");
  const std::vector<double>& shunt = method_ == Method::tree_elimination ? inverse_pivot_ : shunt_workspace_;
  if (shunt.size() != nodes_)
    throw std::logic_error("NodalSystem::factorize_in_place: no shunts written to shunt_workspace()");
  return factorize(conductance, shunt, y.data());
}

void NodalSystem::release_factorization() {
  factorized_ = false;
  if (method_ == Method::tree_elimination) {
    std::vector<double>().swap(inverse_pivot_);
    std::vector<double>().swap(divider_);
  }
  std::vector<double>().swap(inverse_scratch_);
  std::vector<double>().swap(shunt_workspace_);
  inverse_known_ = {};
  std::vector<std::int32_t>().swap(path_scratch_);
}

std::int64_t NodalSystem::factorize(std::span<const double> conductance, std::span<const double> shunt, double* y) {
  if (conductance.size() != edges_ || shunt.size() != nodes_)
    throw std::invalid_argument("NodalSystem::factorize: " + std::to_string(conductance.size()) +
                                " conductances and " + std::to_string(shunt.size()) + " shunts for " +
                                std::to_string(edges_) + " edges and " + std::to_string(nodes_) + " nodes");
  factorized_ = false;
  if (method_ == Method::tree_elimination) allocate_pivots();
  auto bad_value = [](const char* what, std::size_t k, double v) {
    return std::invalid_argument("NodalSystem::factorize: " + std::string(what) + " " + std::to_string(k) +
                                 " is " + std::to_string(v));
  };

  if (method_ == Method::tree_elimination) {
    // Leaves up. inverse_pivot_ first gathers S_i, the conductance to ground of node i's subtree seen
    // from i (its shunt and its children's subtrees through their edges); eliminating child c
    // adds g S_c / (g + S_c) to its parent's, the series conductance of its edge and its
    // subtree: the Schur complement d_p - g^2 / d_c with d_c = g + S_c, but as a sum of
    // positive terms, without the cancellation of the subtraction (exact to a few ulps
    // however the conductances spread, as the series/parallel reduction is). Once node i is
    // eliminated its entry becomes 1 / d_i: the pivots themselves are never read again.
    bool valid = true, singular = false;
    const Elimination elimination{conductance, shunt, inverse_pivot_.data(), divider_.data()};
    sweep_up(&elimination, y, valid, singular);
    if (!valid) {
      // Named as a one-thread pass meets them: shunts by node, then edges leaves up. Shunts
      // given in the pivots' array are gone: a bad one is named after the edges.
      const bool shunts_kept = shunt.data() != inverse_pivot_.data();
      for (std::size_t i = 0; i < nodes_ && shunts_kept; ++i)
        if (!(shunt[i] >= 0 && shunt[i] < std::numeric_limits<double>::infinity())) throw bad_value("shunt of node", i, shunt[i]);
      for (std::size_t k = nodes_; k-- > 0;) {
        const auto c = static_cast<std::size_t>(ordered(k));
        if (parent_[c] < 0) continue;
        const std::size_t e = edge_to_parent(c);
        if (!(conductance[e] > 0 && conductance[e] < std::numeric_limits<double>::infinity()))
          throw bad_value("conductance of edge", e, conductance[e]);
      }
      if (!shunts_kept) throw std::invalid_argument("NodalSystem::factorize: a shunt is negative or not finite");
    }
    if (!singular) {
      factorized_ = true;
      return -1;
    }
    // Name a singular component by its lowest node (as the Cholesky path does): the lowest
    // node whose root is singular. Roots come before their descendants in order_.
    std::vector<std::int32_t> root(nodes_);
    for (std::size_t k = 0; k < nodes_; ++k) {
      const std::int32_t i = ordered(k), p = parent_[static_cast<std::size_t>(i)];
      root[static_cast<std::size_t>(i)] = p < 0 ? i : root[static_cast<std::size_t>(p)];
    }
    for (std::size_t i = 0; i < nodes_; ++i)
      if (!(1 / inverse_pivot_[static_cast<std::size_t>(root[i])] > 0)) return static_cast<std::int64_t>(i);
  }

  // Sparse Cholesky: refill the analysed pattern's values, shunts on the diagonal.
  Cholesky& c = *cholesky_;
  double* value = c.lower.valuePtr();
  std::fill(value, value + c.lower.nonZeros(), 0.0);
  std::fill(grounded_.begin(), grounded_.end(), 0);
  for (std::size_t i = 0; i < nodes_; ++i) {
    if (!(shunt[i] >= 0 && shunt[i] < std::numeric_limits<double>::infinity())) throw bad_value("shunt of node", i, shunt[i]);
    value[c.diagonal_slot[i]] = shunt[i];
    if (shunt[i] > 0) grounded_[static_cast<std::size_t>(component_[i])] = 1;
  }
  for (std::size_t e = 0; e < a_.size(); ++e) {
    const double g = conductance[e];
    if (!(g > 0 && g < std::numeric_limits<double>::infinity())) throw bad_value("conductance of edge", e, g);
    value[c.edge_slot[e]] -= g;
    value[c.diagonal_slot[static_cast<std::size_t>(a_[e])]] += g;
    value[c.diagonal_slot[static_cast<std::size_t>(b_[e])]] += g;
  }
  // A component without a positive shunt is singular exactly; rounding would hide that
  // behind a pivot of either sign, so it is found from the shunts. Its lowest node names it.
  for (std::size_t i = 0; i < nodes_; ++i)
    if (component_[i] == static_cast<std::int32_t>(i) && !grounded_[i]) return static_cast<std::int64_t>(i);
  if (nodes_ == 0) {
    factorized_ = true;
    return -1;
  }
  c.ldlt.factorize(c.lower);
  // Nearly singular (a shunt lost in rounding against the conductances): the component of the
  // lowest node whose pivot vanishes against its diagonal. Past an exact zero pivot Eigen
  // stops, and the later pivots are not set.
  const Eigen::VectorXd& d = c.ldlt.pivots();
  const auto& position = c.ldlt.permutationP().indices();
  Eigen::Index set = d.size();
  if (c.ldlt.info() != Eigen::Success) {
    set = 0;
    while (set < d.size() && d[set] != 0) ++set;
    ++set;
  }
  std::int64_t singular = -1;
  for (std::size_t i = 0; i < nodes_; ++i) {
    const Eigen::Index k = position[static_cast<Eigen::Index>(i)];
    if (k < set && !(d[k] > singular_pivot * value[c.diagonal_slot[i]])) {
      const std::int64_t named = component_[i];
      if (singular < 0 || named < singular) singular = named;
    }
  }
  if (singular >= 0) return singular;
  factorized_ = true;
  if (y) forward(std::span<double>(y, nodes_));
  return -1;
}

void NodalSystem::solve(std::span<const double> b, std::span<double> x) const {
  if (open_roots_)
    throw std::logic_error("NodalSystem::solve: a share of a tree has no potentials of its own (forward, then backward "
                           "from its roots' potentials)");
  if (b.size() != nodes_ || x.size() != nodes_)
    throw std::invalid_argument("NodalSystem::solve: right-hand side of " + std::to_string(b.size()) +
                                " and solution of " + std::to_string(x.size()) + " for " + std::to_string(nodes_) +
                                " nodes");
  if (!factorized_) throw std::logic_error("NodalSystem::solve: no successful factorisation to solve with");
  if (method_ == Method::tree_elimination) {
    // x holds y, the right-hand side as the elimination transforms it: leaves up, each child's
    // current reaches its parent through the divider g / d_c; then roots down, each node from
    // its own row once its parent is known.
    if (x.data() != b.data()) std::copy(b.begin(), b.end(), x.begin());
    bool valid = true, singular = false;
    sweep_up(nullptr, x.data(), valid, singular);
    sweep_down(x.data());
    return;
  }
  // Eigen permutes b into x first (in place if they are one array) and works in x from there.
  const Eigen::Map<const Eigen::VectorXd> rhs(b.data(), static_cast<Eigen::Index>(nodes_));
  Eigen::Map<Eigen::VectorXd> solution(x.data(), static_cast<Eigen::Index>(nodes_));
  solution = cholesky_->ldlt.solve(rhs);
}

void NodalSystem::forward(std::span<double> y) const {
  check_solvable(y.size(), "forward");
  if (method_ == Method::tree_elimination) {
    bool valid = true, singular = false;
    sweep_up(nullptr, y.data(), valid, singular);
    return;
  }
  const Cholesky& c = *cholesky_;
  Eigen::Map<Eigen::VectorXd> v(y.data(), static_cast<Eigen::Index>(nodes_));
  Eigen::VectorXd permuted = c.ldlt.permutationP() * v;
  c.ldlt.matrixL().solveInPlace(permuted);
  v = permuted;
}

void NodalSystem::add_forward(std::span<const std::int32_t> nodes, std::span<const double> values,
                              std::span<double> y) const {
  check_node_list(nodes, values.size(), "add_forward", "values");
  check_solvable(y.size(), "add_forward");
  if (method_ == Method::tree_elimination) {
    // The forward half is linear: a current v added at node j reaches y_j, then its parent
    // through the divider, and so on up to the root (the sweep's own products).
    for (std::size_t k = 0; k < nodes.size(); ++k) {
      double v = values[k];
      for (auto j = static_cast<std::size_t>(nodes[k]);;) {
        y[j] += v;
        const std::int32_t p = parent_[j];
        if (p < 0) break;
        v *= divider_[j];
        j = static_cast<std::size_t>(p);
      }
    }
    return;
  }
  std::vector<double> b(nodes_, 0.0);
  for (std::size_t k = 0; k < nodes.size(); ++k) b[static_cast<std::size_t>(nodes[k])] += values[k];
  forward(b);
  for (std::size_t i = 0; i < nodes_; ++i) y[i] += b[i];
}

void NodalSystem::backward(std::span<const double> y, std::span<double> x) const {
  check_solvable(y.size(), "backward");
  if (x.size() != nodes_)
    throw std::invalid_argument("NodalSystem::backward: solution of " + std::to_string(x.size()) + " for " +
                                std::to_string(nodes_) + " nodes");
  if (x.data() != y.data()) std::copy(y.begin(), y.end(), x.begin());
  if (method_ == Method::tree_elimination) {
    sweep_down(x.data());
    return;
  }
  const Cholesky& c = *cholesky_;
  Eigen::Map<Eigen::VectorXd> v(x.data(), static_cast<Eigen::Index>(nodes_));
  Eigen::VectorXd scaled = c.ldlt.pivots().cwiseInverse().cwiseProduct(v);
  c.ldlt.matrixU().solveInPlace(scaled);
  v = c.ldlt.permutationPinv() * scaled;
}

void NodalSystem::backward_at(std::span<const std::int32_t> nodes, std::span<const double> y,
                              std::span<double> out) const {
  check_node_list(nodes, out.size(), "backward_at", "outputs");
  check_solvable(y.size(), "backward_at");
  if (method_ == Method::tree_elimination) {
    // Each node's value needs its parent's: down its path from the root, by the sweep's own
    // expression (the same bits as backward()).
    std::vector<std::int32_t> path;
    const std::size_t budget = nodes_ / 32 + 64;
    std::size_t walked = 0;
    for (std::size_t k = 0; k < nodes.size() && walked <= budget; ++k) {
      path.clear();
      for (std::int32_t j = nodes[k]; j >= 0; j = parent_[static_cast<std::size_t>(j)]) path.push_back(j);
      walked += path.size();
      double above = 0;
      for (std::size_t q = path.size(); q-- > 0;) {
        const auto i = static_cast<std::size_t>(path[q]);
        if (parent_[i] < 0 && open_roots_)
          above = y[i];
        else
          above = y[i] * inverse_pivot_[i] + (parent_[i] >= 0 ? divider_[i] * above : 0.0);
      }
      out[k] = above;
    }
    if (walked <= budget) return;
  }
  std::vector<double> x(y.begin(), y.end());
  backward(x, x);
  for (std::size_t k = 0; k < nodes.size(); ++k) out[k] = x[static_cast<std::size_t>(nodes[k])];
}

void NodalSystem::check_node_list(std::span<const std::int32_t> nodes, std::size_t values, const char* what,
                                  const char* values_name) const {
  const std::string name = "NodalSystem::" + std::string(what) + ": ";
  if (values != nodes.size())
    throw std::invalid_argument(name + std::to_string(nodes.size()) + " nodes but " + std::to_string(values) + " " +
                                values_name);
  for (const std::int32_t i : nodes)
    if (i < 0 || static_cast<std::size_t>(i) >= nodes_)
      throw std::invalid_argument(name + "node " + std::to_string(i) + " is not below " + std::to_string(nodes_));
}

void NodalSystem::check_solvable(std::size_t size, const char* what) const {
  if (size != nodes_)
    throw std::invalid_argument("NodalSystem::" + std::string(what) + ": vector of " + std::to_string(size) +
                                " for " + std::to_string(nodes_) + " nodes");
  if (!factorized_) throw std::logic_error("NodalSystem::" + std::string(what) + ": no successful factorisation");
}

// ---- the tree's sweeps --------------------------------------------------------------------

std::size_t NodalSystem::task_size_limit(std::size_t nodes) {
  // Below 2^16 nodes a sweep is a few hundred microseconds: threads would only wait. Above,
  // subtrees of at most 1/256 of the nodes: enough tasks for dynamic scheduling to balance
  // two or a few threads, few enough top nodes (those above them) for the serial part.
  if (nodes < (std::size_t{1} << 16)) return 0;
  return std::max<std::size_t>(4096, nodes / 256);
}

std::vector<std::int32_t> NodalSystem::subtree_tasks(std::span<const std::int32_t> parent,
                                                    std::span<const std::int32_t> order) {
  const std::size_t nodes = parent.size();
  std::vector<std::int32_t> task(nodes, -1);
  const std::size_t limit = task_size_limit(nodes);
  if (limit == 0) return task;
  std::vector<std::int32_t> size(nodes, 1);
  for (std::size_t k = nodes; k-- > 0;) {
    const auto c = static_cast<std::size_t>(order[k]);
    if (parent[c] >= 0) size[static_cast<std::size_t>(parent[c])] += size[c];
  }
  std::int32_t tasks = 0;
  for (const std::int32_t node : order) {
    const auto c = static_cast<std::size_t>(node);
    if (static_cast<std::size_t>(size[c]) > limit) continue;
    const std::int32_t p = parent[c];
    task[c] = p >= 0 && task[static_cast<std::size_t>(p)] >= 0 ? task[static_cast<std::size_t>(p)] : tasks++;
  }
  return task;
}

void NodalSystem::plan_subtrees() {
  if (task_size_limit(nodes_) == 0) return;
  std::vector<std::int32_t> identity;
  if (order_.empty()) {
    identity.resize(nodes_);
    std::iota(identity.begin(), identity.end(), 0);
  }
  const std::vector<std::int32_t>& order = order_.empty() ? identity : order_;
  const std::vector<std::int32_t> task = subtree_tasks(parent_, order);
  std::vector<std::int32_t> count;
  for (const std::int32_t c : order) {
    const std::int32_t t = task[static_cast<std::size_t>(c)], p = parent_[static_cast<std::size_t>(c)];
    if (t < 0) {
      top_.push_back(c);
      continue;
    }
    if (p < 0 || task[static_cast<std::size_t>(p)] != t) {  // the task's root: tasks come numbered so
      count.push_back(0);
      top_.push_back(~c);
    }
    ++count[static_cast<std::size_t>(t)];
  }
  task_offset_.assign(count.size() + 1, 0);
  for (std::size_t t = 0; t < count.size(); ++t) task_offset_[t + 1] = task_offset_[t] + count[t];
  task_nodes_.resize(static_cast<std::size_t>(task_offset_.back()));
  std::vector<std::int32_t> cursor(task_offset_.begin(), task_offset_.end() - 1);
  for (const std::int32_t c : order)
    if (const std::int32_t t = task[static_cast<std::size_t>(c)]; t >= 0)
      task_nodes_[static_cast<std::size_t>(cursor[static_cast<std::size_t>(t)]++)] = c;
  // A task whose nodes are one run of consecutive numbers (the subtree order of
  // pulse/lumped_order makes every task one) is that run: its first node is enough.
  task_shift_.resize(count.size());
  bool runs = true;
  for (std::size_t t = 0; t < count.size() && runs; ++t) {
    const auto first = static_cast<std::size_t>(task_offset_[t]), last = static_cast<std::size_t>(task_offset_[t + 1]);
    task_shift_[t] = static_cast<std::int64_t>(task_nodes_[first]) - static_cast<std::int64_t>(first);
    for (std::size_t j = first; j < last && runs; ++j)
      runs = static_cast<std::int64_t>(task_nodes_[j]) == static_cast<std::int64_t>(j) + task_shift_[t];
  }
  if (runs)
    std::vector<std::int32_t>().swap(task_nodes_);
  else
    std::vector<std::int64_t>().swap(task_shift_);
}

void NodalSystem::open_roots() {
  if (method_ != Method::tree_elimination) throw std::logic_error("NodalSystem::open_roots: a tree's elimination only");
  open_roots_ = true;
  factorized_ = false;
}

void NodalSystem::open_edges(std::span<const std::int32_t> edges) {
  open_roots();
  if (edges.empty()) return;
  std::vector<unsigned char> cut(edges_, 0);
  for (const std::int32_t e : edges) {
    if (e < 0 || static_cast<std::size_t>(e) >= edges_)
      throw std::invalid_argument("NodalSystem::open_edges: edge " + std::to_string(e) + " of " + std::to_string(edges_));
    cut[static_cast<std::size_t>(e)] = 1;
  }
  std::size_t found = 0;
  for (std::size_t c = 0; c < nodes_; ++c)
    if (parent_[c] >= 0 && cut[edge_to_parent(c)]) {
      parent_[c] = -1;
      ++found;
    }
  if (found != edges.size())
    throw std::invalid_argument("NodalSystem::open_edges: " + std::to_string(edges.size() - found) +
                                " of the edges join no node to its parent (or come twice)");
  // The sweeps' tasks anew: subtrees of the forest as it now is.
  top_.clear();
  task_nodes_.clear();
  task_offset_.clear();
  task_shift_.clear();
  plan_subtrees();
}

double NodalSystem::open_root_conductance(std::size_t root) const {
  if (!open_roots_ || root >= nodes_ || parent_[root] >= 0)
    throw std::invalid_argument("NodalSystem::open_root_conductance: node " + std::to_string(root) +
                                " is not an open root");
  check_solvable(nodes_, "open_root_conductance");
  return inverse_pivot_[root];
}

bool NodalSystem::parallel_sweeps() const { return threads_ > 1 && !task_offset_.empty(); }

void NodalSystem::sweep_up(const Elimination* elimination, double* y, bool& valid, bool& singular) const {
  constexpr double infinity = std::numeric_limits<double>::infinity();
  const Elimination* el = elimination;
  auto start = [&](std::size_t c, bool& ok) {
    const double s = el->shunt[c];
    ok &= s >= 0 && s < infinity;
    el->inverse_pivot[c] = s;  // S_c, until c is eliminated
  };
  // One node of the sweep: its subtree is eliminated, its pivot final once its edge is added.
  auto up = [&](std::size_t c, bool& ok, bool& lost) {
    const std::int32_t p = parent_[c];
    if (p < 0) {
      if (open_roots_) return;  // S_r and y_r go on to the rest of the tree
      // A root's S is its whole component's conductance to ground: a sum of non-negative
      // terms, zero exactly when no node of the component has a shunt.
      if (el) {
        lost |= !(el->inverse_pivot[c] > 0);
        el->inverse_pivot[c] = 1 / el->inverse_pivot[c];
      }
      return;
    }
    if (el) {
      const double g = el->conductance[edge_to_parent(c)];
      ok &= g > 0 && g < infinity;
      const double s = el->inverse_pivot[c], inverse = 1 / (g + s);
      // What the sweeps multiply by: no division left in a solve.
      el->inverse_pivot[c] = inverse;
      el->divider[c] = g * inverse;
      el->inverse_pivot[static_cast<std::size_t>(p)] += g * s * inverse;
    }
    if (y) y[static_cast<std::size_t>(p)] += divider_[c] * y[c];
  };
  bool ok = true, lost = false;
  if (!parallel_sweeps()) {
    if (el)
      for (std::size_t i = 0; i < nodes_; ++i) start(i, ok);
    if (order_.empty())
      for (std::size_t k = nodes_; k-- > 0;) up(k, ok, lost);
    else
      for (std::size_t k = nodes_; k-- > 0;) up(static_cast<std::size_t>(order_[k]), ok, lost);
  } else {
    // Each task's nodes but its root in parallel (a node's children are in its own task);
    // then the top and the tasks' roots, leaves up, serially: every pivot sums its children
    // in the order of one thread.
    if (el)
      for (const std::int32_t c : top_)
        if (c >= 0) start(static_cast<std::size_t>(c), ok);
    const auto tasks = static_cast<std::int64_t>(task_offset_.size()) - 1;
    bool tasks_ok = true;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads_) reduction(&& : tasks_ok)
    for (std::int64_t t = 0; t < tasks; ++t) {
      const auto first = static_cast<std::size_t>(task_offset_[static_cast<std::size_t>(t)]);
      const auto last = static_cast<std::size_t>(task_offset_[static_cast<std::size_t>(t) + 1]);
      bool task_ok = true, unused = false;
      const TaskNodes nodes = task_nodes(static_cast<std::size_t>(t));
      if (el)
        for (std::size_t j = first; j < last; ++j) start(nodes[j], task_ok);
      for (std::size_t j = last; j-- > first + 1;) up(nodes[j], task_ok, unused);
      tasks_ok = tasks_ok && task_ok;
    }
    ok &= tasks_ok;
    for (std::size_t k = top_.size(); k-- > 0;) {
      const std::int32_t c = top_[k];
      up(static_cast<std::size_t>(c >= 0 ? c : ~c), ok, lost);
    }
  }
  valid = ok;
  singular = lost;
}

void NodalSystem::sweep_down(double* x) const {
  auto down = [&](std::size_t i) {
    const std::int32_t p = parent_[i];
    if (p < 0 && open_roots_) return;  // the potential the rest of the tree found
    x[i] = x[i] * inverse_pivot_[i] + (p >= 0 ? divider_[i] * x[static_cast<std::size_t>(p)] : 0.0);
  };
  if (!parallel_sweeps()) {
    if (order_.empty())
      for (std::size_t k = 0; k < nodes_; ++k) down(k);
    else
      for (std::size_t k = 0; k < nodes_; ++k) down(static_cast<std::size_t>(order_[k]));
    return;
  }
  for (const std::int32_t c : top_) down(static_cast<std::size_t>(c >= 0 ? c : ~c));
  const auto tasks = static_cast<std::int64_t>(task_offset_.size()) - 1;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads_)
  for (std::int64_t t = 0; t < tasks; ++t) {
    const auto first = static_cast<std::size_t>(task_offset_[static_cast<std::size_t>(t)]);
    const auto last = static_cast<std::size_t>(task_offset_[static_cast<std::size_t>(t) + 1]);
    const TaskNodes nodes = task_nodes(static_cast<std::size_t>(t));
    for (std::size_t j = first + 1; j < last; ++j) down(nodes[j]);
  }
}

void NodalSystem::inverse_diagonal(std::span<const std::int32_t> nodes, std::span<double> out) const {
  check_node_list(nodes, out.size(), "inverse_diagonal", "outputs");
  if (!factorized_) throw std::logic_error("NodalSystem::inverse_diagonal: no successful factorisation to use");
  if (open_roots_) throw std::logic_error("NodalSystem::inverse_diagonal: a share of a tree holds no whole inverse");
  if (nodes.empty()) return;

  // The scratch is back to its resting state after every call; an exception (bad_alloc of the
  // path) leaves it unknown, so it is dropped and rebuilt at the next call.
  try {
    if (method_ == Method::tree_elimination) {
      // The selected inversion. Eliminating the nodes leaves first (order_ backwards) factors
      // the system as K = L D L^T with D = diag(d), 1/d = inverse_pivot_, and L unit lower triangular in
      // that order with one entry below the diagonal in column c, at its parent p:
      //   L_pc = K_pc / d_c = -g_c / d_c      (g_c the conductance of the edge to the parent),
      // so l_c = -g_c / d_c = -g_c / (g_c + S_c), with S_c the conductance of c's subtree (see
      // factorize): the voltage divider of the edge and the subtree, in (0, 1]. From
      // L^T Sigma = D^-1 L^-1 for Sigma = K^-1 (Takahashi, Fagan & Chin 1973; Erisman &
      // Tinney 1975): Sigma = D^-1 L^-1 + (I - L^T) Sigma, and as L^-1 is unit lower
      // triangular, entry (c, c) and entry (c, p) (above the diagonal of L^-1, zero there) read
      //   Sigma_cc = 1/d_c - l_c Sigma_pc,      Sigma_cp = -l_c Sigma_pp,
      // hence, by symmetry,
      //   Sigma_cc = 1/d_c + (g_c / d_c)^2 Sigma_pp,      Sigma_rr = 1/d_r at a root r.
      // As circuits: a unit current into c raises p by Sigma_pc = (g_c / d_c) Sigma_pp (the
      // part g_c / d_c of it passes the edge), and c's row with its subtree eliminated,
      // d_c x_c - g_c x_p = 1, gives x_c = 1/d_c + (g_c / d_c) x_p. Two positive terms, no
      // cancellation: as exact as the pivots, a few ulps per level of the tree.
      // Each requested node climbs to the nearest ancestor already known (or past its root),
      // stacking the path, and comes down it; the nodes computed stay known for the others.
      // A step of that walk is a chain of dependent cache misses (about 150 ns measured on the
      // 3.8 M-node tree of bench/nodal_system_speed), where one pass over every node in
      // order_ streams (about 4 ns a node): past 1/32 of the nodes on the paths (and 64 more,
      // for small systems, which are in cache), the walk gives way to the pass, so a call
      // costs at most about twice the cheaper of the two. Both compute each node by the same
      // expression from the same parent's value, so they agree to the bit.
      // The walk keeps the nodes it has computed in a small map (a dense array would hold 8 B
      // a node through the whole run for the few hundred coupling nodes' paths); the pass
      // takes a dense array for the call alone.
      auto& known = inverse_known_;
      auto& path = path_scratch_;
      const std::size_t budget = nodes_ / 32 + 64;
      auto own = [&](std::size_t c, auto&& sigma_of) {
        const std::int32_t p = parent_[c];
        if (p < 0) return inverse_pivot_[c];
        const double divider = divider_[c];
        return inverse_pivot_[c] + divider * divider * sigma_of(p);
      };
      known.clear();
      path.clear();
      bool walked = true;
      for (std::size_t k = 0; k < nodes.size() && walked; ++k) {
        const std::size_t bottom = path.size();
        for (std::int32_t j = nodes[k]; j >= 0 && !known.contains(j); j = parent_[static_cast<std::size_t>(j)]) {
          path.push_back(j);
          if (path.size() > budget) {
            walked = false;
            break;
          }
        }
        if (!walked) break;
        for (std::size_t q = path.size(); q-- > bottom;)
          known.emplace(path[q], own(static_cast<std::size_t>(path[q]), [&](std::int32_t p) { return known.at(p); }));
        out[k] = known.at(nodes[k]);
      }
      if (!walked) {
        std::vector<double> sigma(nodes_);
        for (std::size_t k = 0; k < nodes_; ++k) {
          const auto c = static_cast<std::size_t>(ordered(k));
          sigma[c] = own(c, [&](std::int32_t p) { return sigma[static_cast<std::size_t>(p)]; });
        }
        for (std::size_t k = 0; k < nodes.size(); ++k) out[k] = sigma[static_cast<std::size_t>(nodes[k])];
      }
      known.clear();
      path.clear();
      return;
    }

    // Sparse Cholesky: P K P^T = L D L^T, so Sigma_ii = y^T D^-1 y with y = L^-1 e_k, k node
    // i's position in the elimination order. The forward solve with a unit vector only
    // touches the path from k up the elimination tree: the rows of column j of L are
    // ancestors of j, the lowest of them its parent (Gilbert 1994; Davis 2006, ch. 4). So the
    // walk goes up that path in increasing order, each y_j final when reached, adds
    // y_j^2 / d_j (positive terms) and leaves y_j at 0 again behind it.
    const Cholesky& c = *cholesky_;
    const auto lower_view = c.ldlt.matrixL();
    const Eigen::SparseMatrix<double>& lower = lower_view.nestedExpression();
    const Eigen::VectorXd& d = c.ldlt.pivots();
    const auto& position = c.ldlt.permutationP().indices();
    const auto n = static_cast<Eigen::Index>(nodes_);
    auto& y = inverse_scratch_;
    if (y.size() != nodes_) y.assign(nodes_, 0.0);
    for (std::size_t k = 0; k < nodes.size(); ++k) {
      Eigen::Index j = position[nodes[k]];
      y[static_cast<std::size_t>(j)] = 1;
      double sum = 0;
      while (j < n) {
        const double yj = y[static_cast<std::size_t>(j)];
        y[static_cast<std::size_t>(j)] = 0;
        sum += yj * yj / d[j];
        Eigen::Index next = n;
        for (Eigen::SparseMatrix<double>::InnerIterator it(lower, j); it; ++it) {
          const Eigen::Index r = it.row();
          if (r <= j) continue;  // a stored unit diagonal, if any
          y[static_cast<std::size_t>(r)] -= it.value() * yj;
          next = std::min(next, r);
        }
        j = next;
      }
      out[k] = sum;
    }
  } catch (...) {
    inverse_scratch_ = {};
    inverse_known_ = {};
    path_scratch_ = {};
    throw;
  }
}

}  // namespace hemotree
