#include "pulse/legendre_basis.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/errors.hpp"

#include <Eigen/Eigenvalues>

namespace hemotree {

GaussLegendre gauss_legendre(int n) {
  // Golub-Welsch: the nodes are the eigenvalues of the Jacobi matrix of the Legendre
  // recurrence, the weights 2 v_0^2 from its normalised eigenvectors.
  Eigen::MatrixXd jacobi = Eigen::MatrixXd::Zero(n, n);
  for (int k = 1; k < n; ++k) {
    const double b = k / std::sqrt(4.0 * k * k - 1.0);
    jacobi(k, k - 1) = jacobi(k - 1, k) = b;
  }
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(jacobi);
  GaussLegendre rule;
  rule.nodes = eig.eigenvalues();
  rule.weights = 2.0 * eig.eigenvectors().row(0).array().square().transpose();
  return rule;
}

double legendre(int n, double x) {
  double previous = 1.0, current = x;
  if (n == 0) return previous;
  for (int k = 1; k < n; ++k) {
    const double next = ((2 * k + 1) * x * current - k * previous) / (k + 1);
    previous = current;
    current = next;
  }
  return current;
}

double legendre_derivative(int n, double x) {
  // P_n' = sum over k = n-1, n-3, ... of (2k + 1) P_k: no division by 1 - x^2 at the ends.
  double d = 0;
  for (int k = n - 1; k >= 0; k -= 2) d += (2 * k + 1) * legendre(k, x);
  return d;
}

ModalBasis modal_basis(int degree, int points) {
  if (degree < 0 || degree > 30) throw InputError("the polynomial degree must lie in 0..30");
  ModalBasis b;
  b.degree = degree;
  b.points = points > 0 ? points : std::max(degree + 1, (3 * degree + 1) / 2);
  b.rule = gauss_legendre(b.points);
  const int modes = degree + 1;
  b.at_points.resize(b.points, modes);
  b.weak_derivative.resize(modes, b.points);
  b.projection.resize(modes, b.points);
  b.left.resize(modes);
  b.right.resize(modes);
  b.inverse_mass.resize(modes);
  for (int j = 0; j < modes; ++j) {
    b.inverse_mass(j) = (2 * j + 1) / 2.0;
    b.left(j) = j % 2 == 0 ? 1.0 : -1.0;
    b.right(j) = 1.0;
    for (int q = 0; q < b.points; ++q) {
      const double xi = b.rule.nodes(q), w = b.rule.weights(q);
      b.at_points(q, j) = legendre(j, xi);
      b.weak_derivative(j, q) = b.inverse_mass(j) * legendre_derivative(j, xi) * w;
      b.projection(j, q) = b.inverse_mass(j) * legendre(j, xi) * w;
    }
  }
  return b;
}

}  // namespace hemotree
