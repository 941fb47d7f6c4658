// The nodal system of a network's harmonics: the same weighted Laplacian plus shunts as
// nodal_system.hpp, with complex admittances, for the amplitudes X of one angular frequency
// omega (x(t) = Re X e^{i omega t}):
//
//   (sum_e y_e (u_a - u_b)(u_a - u_b)^T + diag(s)) X = B,    y_e, s_i, B_i complex.
//
// The matrix is complex symmetric, not Hermitian, so the real Cholesky does not apply. On a
// forest the elimination from the leaves up makes no fill, as for the real system:
// O(nodes), pivots d_i = s_i + sum_e y_e less what each eliminated child gives up
// (y_e^2 / d_child). On any other graph, Eigen's SparseLU (COLAMD ordering). Each solve
// factorises afresh: every harmonic has its own admittances.
#pragma once

#include <complex>
#include <cstdint>
#include <span>
#include <vector>

namespace hemotree {

using Complex = std::complex<double>;

// Edges join nodes a[e] and b[e] (a[e] != b[e], below nodes); admittance per edge, shunt and
// current per node. Returns the node potentials. std::invalid_argument for sizes that do not
// match, an edge out of range, or a singular system (a zero pivot: a part of the network with
// no admittance to ground), naming the node.
std::vector<Complex> solve_harmonic_system(std::size_t nodes, std::span<const std::int32_t> a,
                                           std::span<const std::int32_t> b, std::span<const Complex> admittance,
                                           std::span<const Complex> shunt, std::span<const Complex> current);

}  // namespace hemotree
