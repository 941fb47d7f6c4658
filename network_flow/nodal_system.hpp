// The one linear system behind every network-flow problem of hemotree, in the node
// potentials x (pressures):
//
//   (sum_e g_e (u_a - u_b)(u_a - u_b)^T + diag(s)) x = b
//
// a graph Laplacian weighted by the edges' conductances g_e (vessels: 1/R, or
// 1/(R + 3L/(2 dt)) for a step of the 0D vessels) plus a diagonal of shunts s_i (conductances
// to ground: outlets, C/dt of compliances). It is symmetric positive definite when every
// connected component has a positive shunt. The steady flow (no time derivative), the
// compliance balance and each implicit step of the 0D vessels are this system with other
// conductances and shunts.
//
// The graph is fixed at construction; conductances and shunts change with every
// factorisation. On a forest the factorisation is the elimination from the leaves up, which
// makes no fill: O(nodes) to factorise and to solve. On any other graph (loops, parallel
// edges) it is Eigen's sparse Cholesky (SimplicialLDLT, AMD ordering, the pattern analysed
// once). Both give the same solution to rounding (tests/test_nodal_system).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <unordered_map>
#include <vector>

namespace hemotree {

class NodalSystem {
 public:
  enum class Method { automatic, tree_elimination, sparse_cholesky };

  // Edges join nodes a[e] and b[e] (indices below nodes, a[e] != b[e]; std::invalid_argument
  // otherwise). automatic: tree_elimination on a forest, else sparse_cholesky;
  // tree_elimination on a graph that is not a forest is std::invalid_argument.
  NodalSystem();  // of no nodes (defined with the Cholesky type complete)
  NodalSystem(std::size_t nodes, std::vector<std::int32_t> a, std::vector<std::int32_t> b,
              Method method = Method::automatic);
  ~NodalSystem();
  NodalSystem(NodalSystem&&) noexcept;
  NodalSystem& operator=(NodalSystem&&) noexcept;

  std::size_t node_count() const { return nodes_; }
  std::size_t edge_count() const { return edges_; }
  Method method() const { return method_; }  // the one in use: never automatic

  // conductance: per edge, > 0; shunt: per node, >= 0. Returns -1, or a node of a connected
  // component that has no path to ground (no positive shunt: the system is singular), its
  // lowest; the sparse Cholesky also names a component whose shunts are lost in rounding
  // against its conductances (a pivot below 1e-13 of its diagonal).
  std::int64_t factorize(std::span<const double> conductance, std::span<const double> shunt);
  // x = system^-1 b with the last factorisation (x may alias b).
  void solve(std::span<const double> b, std::span<double> x) const;

  // The solve in its two halves, K = P^T L D L^T P: forward, y = L^-1 P b, and backward,
  // x = P^T L^-T D^-1 y. A step of the 0D vessels knows most of its right-hand side before
  // the 1D vessels' part of it: the forward half of the known part goes with the
  // factorisation (one pass), the rest is added later through add_forward, which on a tree
  // touches only the nodes' paths to their roots, and one backward half gives every node.
  // What the 1D vessels need in between, the potential at a few nodes, is backward_at.
  // factorize, and y = L^-1 P y in the same pass (in place; y of node_count()).
  std::int64_t factorize_forward(std::span<const double> conductance, std::span<const double> shunt,
                                 std::span<double> y);
  // The same with shunts the caller wrote into shunt_workspace() (one per node) since the
  // last factorisation: on a tree that is the pivots' own array, which the elimination starts
  // from and overwrites, so a caller that forms its shunts anew for every factorisation (a
  // 0D step) holds no array of them (8 bytes a node). Their values are gone after the call.
  std::span<double> shunt_workspace();
  std::int64_t factorize_in_place(std::span<const double> conductance);
  std::int64_t factorize_forward_in_place(std::span<const double> conductance, std::span<double> y);
  void forward(std::span<double> y) const;  // y = L^-1 P y, in place
  // Frees a tree's factorisation and the inverse diagonal's scratch (16 and 8 bytes a node)
  // until the next factorize: for a caller that holds a system across a phase that needs
  // neither (a run's cycle end). Solves refuse until then, as before any factorisation.
  void release_factorization();
  // y += L^-1 P b for b zero but at `nodes` (values[k] at nodes[k]; repeats add).
  void add_forward(std::span<const std::int32_t> nodes, std::span<const double> values, std::span<double> y) const;
  void backward(std::span<const double> y, std::span<double> x) const;  // x may alias y
  // x_i = (P^T L^-T D^-1 y)_i at each node i of `nodes` into out: on a tree only the nodes on
  // their paths to their roots (past 1/32 of all, the whole backward half).
  void backward_at(std::span<const std::int32_t> nodes, std::span<const double> y, std::span<double> out) const;

  // A share of a larger tree (distributed/tree_share.hpp): every root of this forest hangs
  // from a node held elsewhere. The elimination then leaves at each root r, in place of its
  // pivot, S_r, its subtree's conductance to ground seen from r (its shunt and its children
  // through their edges: open_root_conductance), the forward half leaves y_r summed over its
  // subtree, and the backward half takes x_r as given (the potential the rest of the tree
  // found for it; solve(), which would need them, is refused: std::logic_error). Every other
  // node's arithmetic is the closed system's, so that a tree cut into shares and swept share
  // by share gives the bits of the whole. Tree elimination only (std::logic_error otherwise);
  // the singular check is the rest of the tree's.
  // The same where this forest's roots and the rest of the tree are not apart: each given
  // edge (an edge to a parent, by its number) joins a node here to one held elsewhere, so the
  // node below it is a root, held open (and the node above too, where no other edge reaches it).
  // The edges keep their numbers: conductances are still given for every edge, and these are
  // not read. std::invalid_argument for an edge that is not one to a parent.
  void open_edges(std::span<const std::int32_t> edges);
  void open_roots();
  bool roots_open() const { return open_roots_; }
  double open_root_conductance(std::size_t root) const;

  // Threads for the tree elimination's sweeps: subtrees in parallel, the top of the tree and
  // each subtree's root serially in the one-thread order, so the bits do not depend on it.
  void set_threads(int threads) { threads_ = threads; }
  // The largest subtree a sweep's task takes on a forest of `nodes` (0: no tasks, one thread
  // sweeps): the subtrees of at most this many nodes whose parent roots a larger one.
  static std::size_t task_size_limit(std::size_t nodes);
  // The tasks themselves, on a forest given by each node's parent (-1 at roots) and an order
  // with every parent before its children: per node its task, the largest subtree within the
  // limit that holds it (numbered as their roots come in `order`), or -1 above them (every
  // node below the limit's threshold). The sweeps' plan, and what an owner numbers its nodes
  // by to keep each task's together (pulse/lumped_order).
  static std::vector<std::int32_t> subtree_tasks(std::span<const std::int32_t> parent,
                                                 std::span<const std::int32_t> order);
  // (system^-1)_ii for each node i of `nodes` (any order, repeats allowed), with the last
  // factorisation, into out (of nodes' size): each node's own response, the potential that a
  // unit current into it alone raises there (the impedance to ground seen from the node).
  // std::invalid_argument for a size mismatch or a node not below node_count(), before
  // anything is written; std::logic_error without a successful factorisation.
  //   Tree elimination: the selected inversion (Takahashi, Fagan & Chin 1973), down from
  // each requested node's root to it, sharing what one node computed with the next: the work
  // is the number of distinct nodes on the paths from the requested nodes to their roots;
  // past 1/32 of the nodes, one O(nodes) pass over all of them instead. So O(nodes) at most,
  // for any request.
  // Sparse Cholesky: per requested node, the forward solve with the unit vector restricted to
  // its path up the elimination tree (O(path x column counts), not a full solve).
  // Not thread-safe against itself: it works in scratch kept in the system (8 bytes a node,
  // allocated at the first call, none after), so two calls on one system must not overlap;
  // solve() does not touch it and may run alongside.
  void inverse_diagonal(std::span<const std::int32_t> nodes, std::span<double> out) const;

 private:
  std::size_t nodes_ = 0, edges_ = 0;
  // The edges' nodes: kept for the sparse Cholesky's refill; a tree's elimination needs only
  // each node's parent edge (below), and frees them once planned.
  std::vector<std::int32_t> a_, b_;
  Method method_ = Method::automatic;
  // Tree elimination: the nodes with every parent before its children (empty: their own
  // order, where every node hangs from a lower one; else the reverse of the order in which
  // peeling leaves removes them), each node's parent and the edge to it (-1 at roots; empty
  // where every node's is the one numbered before it), and the pivots.
  std::vector<std::int32_t> order_, parent_, parent_edge_;
  std::int32_t ordered(std::size_t k) const { return order_.empty() ? static_cast<std::int32_t>(k) : order_[k]; }
  // The edge from non-root node c to its parent (parent_edge_ empty: c - 1).
  std::size_t edge_to_parent(std::size_t c) const {
    return parent_edge_.empty() ? c - 1 : static_cast<std::size_t>(parent_edge_[c]);
  }
  // Per node: 1 / d_i, d_i its pivot after eliminating its subtree, and g_i / d_i (g_i its
  // edge to the parent: the voltage divider of that edge and the subtree).
  std::vector<double> inverse_pivot_, divider_;
  std::vector<double> shunt_workspace_;  // shunt_workspace() where the pivots are not (sparse Cholesky)
  void allocate_pivots();  // the tree's pivot arrays, where released
  // The sweeps' parallel plan: subtrees of at most a few ten thousand nodes whose parent (if
  // any) roots a larger one are tasks, each with its nodes in elimination order (task_nodes_
  // from task_offset_[t], the task's root first); top_ lists, in elimination order, the nodes
  // of no task and (as ~node) the tasks' roots: what the serial part of a sweep visits.
  // Where every task's nodes are consecutive numbers (the subtree order's tasks are),
  // task_nodes_ is empty and task t's place j holds node j + task_shift_[t].
  std::vector<std::int32_t> task_nodes_, task_offset_, top_;
  std::vector<std::int64_t> task_shift_;
  struct TaskNodes {  // the node at place j of one task
    const std::int32_t* listed;
    std::int64_t shift;
    std::size_t operator[](std::size_t j) const {
      return static_cast<std::size_t>(listed ? listed[j] : static_cast<std::int64_t>(j) + shift);
    }
  };
  TaskNodes task_nodes(std::size_t t) const {
    return task_nodes_.empty() ? TaskNodes{nullptr, task_shift_[t]} : TaskNodes{task_nodes_.data(), 0};
  }
  int threads_ = 1;
  bool open_roots_ = false;
  bool parallel_sweeps() const;
  std::int64_t factorize(std::span<const double> conductance, std::span<const double> shunt, double* y);
  void check_solvable(std::size_t size, const char* what) const;  // a vector of every node, and a factorisation
  // std::invalid_argument unless `values` matches the node list and every node is below node_count().
  void check_node_list(std::span<const std::int32_t> nodes, std::size_t values, const char* what,
                       const char* values_name) const;
  void plan_subtrees();
  // The tree's sweeps: leaves up, eliminating (where `elimination` is given: the pivots from
  // its conductances and shunts, into its arrays) and the forward half of y (where given);
  // roots down, the backward half.
  struct Elimination {
    std::span<const double> conductance, shunt;
    double *inverse_pivot, *divider;
  };
  void sweep_up(const Elimination* elimination, double* y, bool& valid, bool& singular) const;
  void sweep_down(double* x) const;
  struct Cholesky;  // Eigen's factorisation, out of this header
  std::unique_ptr<Cholesky> cholesky_;
  // Sparse Cholesky: each node's component, named by its lowest node, and per component
  // whether it has a shunt (scratch). Whether the last factorisation succeeded.
  std::vector<std::int32_t> component_;
  std::vector<unsigned char> grounded_;
  bool factorized_ = false;
  // inverse_diagonal's scratch, empty or back to zero after every call: per position of the
  // Cholesky order (the forward solve, 0 outside its path); on a tree Sigma_ii of the nodes
  // walked, and the path stack.
  mutable std::vector<double> inverse_scratch_;
  mutable std::unordered_map<std::int32_t, double> inverse_known_;
  mutable std::vector<std::int32_t> path_scratch_;
};

}  // namespace hemotree
