// The nodal system of a network's harmonics, for the amplitudes X of one angular frequency
// omega (x(t) = Re X e^{i omega t}): each edge e from node a to node b a two-port, the flows
// it draws out of its nodes given their potentials,
//
//   [J_a; J_b] = Y_e [X_a; X_b],   Y_e = [[y_aa, y_ab], [y_ba, y_bb]] complex,
//
// and each node a shunt s_i to ground and an injected current B_i:
//   sum_e (what e draws out of i) + s_i X_i = B_i.
// A passive, reciprocal edge (a line at rest) is y_aa = y_bb = -y_ab = -y_ba plus shunts; a
// line with a mean flow through it is not reciprocal (y_ab != y_ba), so the matrix is
// neither Hermitian nor symmetric. On a forest the elimination from the leaves up makes no
// fill, as for the real system (nodal_system.hpp): O(nodes), a child i handing its parent p
// y_pi y_ip / d_i of its pivot. On any other graph, Eigen's SparseLU (COLAMD ordering). The
// graph's structure (checked, and a forest's elimination order) is set once for every
// frequency; each solve factorises afresh: every harmonic has its own admittances.
#pragma once

#include <complex>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace hemotree {

using Complex = std::complex<double>;

// 1 / z as conj(z) / |z|^2: libgcc's complex division (__divdc3) rescales against overflow
// and took about a tenth of the harmonic solve's time; the admittances, impedances and
// pivots of vessels lie far inside 1e-100 < |z| < 1e100, where |z|^2 neither overflows nor
// underflows. Outside it (and at 0, inf, NaN), the library's division.
inline Complex reciprocal(Complex z) {
  const double size = std::norm(z);
  if (!(size >= 1e-200 && size <= 1e200)) return 1.0 / z;
  const double inverse = 1.0 / size;
  return {z.real() * inverse, -z.imag() * inverse};
}

// A zero pivot: the part of the network that holds `node` has no admittance to ground.
struct SingularHarmonicSystem : std::invalid_argument {
  SingularHarmonicSystem(std::size_t node_, const std::string& what) : std::invalid_argument(what), node(node_) {}
  std::size_t node;
};

struct TwoPort {
  Complex aa, ab, ba, bb;
  // The reciprocal edge of admittance y: what a resistor or a line's series branch draws.
  static TwoPort series(Complex y) { return {y, -y, -y, y}; }
};

// Edges join nodes a[e] and b[e] (a[e] != b[e], below nodes). std::invalid_argument for an
// edge out of range.
class HarmonicSystem {
 public:
  HarmonicSystem(std::size_t nodes, std::vector<std::int32_t> a, std::vector<std::int32_t> b);
  std::size_t nodes() const { return nodes_; }
  std::size_t edges() const { return a_.size(); }
  // One two-port per edge, a shunt and a current per node: the node potentials.
  // std::invalid_argument for sizes that do not match, or a singular system (a zero pivot: a
  // part of the network with no admittance to ground), naming the node.
  std::vector<Complex> solve(std::span<const TwoPort> edge, std::span<const Complex> shunt,
                             std::span<const Complex> current) const;
  // The same in the caller's storage: shunt is overwritten (on a forest with the pivots'
  // reciprocals, a root's its pivot), current with the potentials.
  void solve_in_place(std::span<const TwoPort> edge, std::span<Complex> shunt, std::span<Complex> current) const;

  // A forest's solve from what its elimination reads of each edge once the diagonal is summed:
  // the caller adds every edge's y_aa to shunt[a] and y_bb to shunt[b], edge by edge in their
  // order (as solve_in_place does first), and keeps only (y_ab, y_ba): half the two-ports'
  // memory, and the same numbers. std::logic_error on a graph that is not a forest.
  struct Coupling {
    Complex ab, ba;
  };
  bool forest() const { return forest_; }
  std::span<const std::int32_t> edge_a() const { return a_; }
  std::span<const std::int32_t> edge_b() const { return b_; }
  void solve_forest_in_place(std::span<const Coupling> coupling, std::span<Complex> diagonal,
                             std::span<Complex> current) const;
  // The same solve in its two sweeps, for a caller that works between them (a share of a
  // larger forest): leaves up, each non-root node's diagonal becomes its pivot's reciprocal
  // and hands its parent its terms; roots down, current becomes the potentials.
  void eliminate_forest_up(std::span<const Coupling> coupling, std::span<Complex> diagonal,
                           std::span<Complex> current) const;
  void substitute_forest_down(std::span<const Coupling> coupling, std::span<const Complex> diagonal,
                              std::span<Complex> current) const;

  // A share of a larger forest (distributed/harmonic_tree_share.hpp): every root of this
  // forest hangs from a node held elsewhere. The sweep up then leaves at each root r its
  // pivot d_r (its diagonal less its children's terms) and its current y_r as they are, with
  // no check (the rest of the forest's), and the sweep down takes x_r from current[r] as
  // given; solve_forest_in_place, which would need them, is refused (std::logic_error). Every
  // other node's arithmetic is the closed forest's, so a forest swept share by share gives
  // the bits of the whole.
  void open_roots() { open_roots_ = true; }
  bool roots_open() const { return open_roots_; }

 private:
  void solve_forest(std::span<const TwoPort> edge, std::span<Complex> pivot, std::span<Complex> x) const;
  // The elimination itself, the diagonal summed: of each edge (a TwoPort or a Coupling) it
  // reads ab and ba.
  template <class Edge>
  void eliminate_forest(std::span<const Edge> edge, std::span<Complex> pivot, std::span<Complex> x) const;
  template <class Edge>
  void sweep_up(std::span<const Edge> edge, std::span<Complex> pivot, std::span<Complex> x) const;
  template <class Edge>
  void sweep_down(std::span<const Edge> edge, std::span<const Complex> pivot, std::span<Complex> x) const;
  void check_forest_sizes(std::size_t couplings, std::size_t diagonal, std::size_t current) const;
  void solve_sparse(std::span<const TwoPort> edge, std::span<const Complex> shunt, std::span<Complex> x) const;

  std::size_t nodes_;
  std::vector<std::int32_t> a_, b_;
  bool forest_ = false, open_roots_ = false;
  // A forest's elimination order (leaves first; empty where every parent's label lies below
  // its children's: the labels from the highest down) and each node's edge to its parent (-1
  // at a root).
  std::vector<std::int32_t> order_, parent_edge_;
  std::size_t eliminated(std::size_t k) const {
    return order_.empty() ? nodes_ - 1 - k : static_cast<std::size_t>(order_[k]);
  }
};

// One solve: HarmonicSystem(nodes, a, b).solve(edge, shunt, current).
std::vector<Complex> solve_harmonic_system(std::size_t nodes, std::span<const std::int32_t> a,
                                           std::span<const std::int32_t> b, std::span<const TwoPort> edge,
                                           std::span<const Complex> shunt, std::span<const Complex> current);

}  // namespace hemotree
