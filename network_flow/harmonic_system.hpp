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
// y_pi y_ip / d_i of its pivot. On any other graph, Eigen's SparseLU (COLAMD ordering). Each
// solve factorises afresh: every harmonic has its own admittances.
#pragma once

#include <complex>
#include <cstdint>
#include <span>
#include <vector>

namespace hemotree {

using Complex = std::complex<double>;

struct TwoPort {
  Complex aa, ab, ba, bb;
  // The reciprocal edge of admittance y: what a resistor or a line's series branch draws.
  static TwoPort series(Complex y) { return {y, -y, -y, y}; }
};

// Edges join nodes a[e] and b[e] (a[e] != b[e], below nodes); one two-port per edge, a shunt
// and a current per node. Returns the node potentials. std::invalid_argument for sizes that
// do not match, an edge out of range, or a singular system (a zero pivot: a part of the
// network with no admittance to ground), naming the node.
std::vector<Complex> solve_harmonic_system(std::size_t nodes, std::span<const std::int32_t> a,
                                           std::span<const std::int32_t> b, std::span<const TwoPort> edge,
                                           std::span<const Complex> shunt, std::span<const Complex> current);

}  // namespace hemotree
