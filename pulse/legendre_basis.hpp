// The modal Legendre basis of one reference element [-1, 1] and the Gauss-Legendre
// quadrature that integrates with it: everything the DG operator needs, as small matrices
// that act on all elements at once.
#pragma once

#include <Eigen/Dense>

namespace hemotree {

struct GaussLegendre {
  Eigen::VectorXd nodes, weights;
};
// n-point rule, exact for polynomials of degree 2n - 1 (Golub-Welsch).
GaussLegendre gauss_legendre(int points);

// P_n(x) and P_n'(x) by the three-term recurrence.
double legendre(int n, double x);
double legendre_derivative(int n, double x);

struct ModalBasis {
  int degree = 0;   // p: modes 0..p
  int points = 0;   // quadrature points per element
  GaussLegendre rule;
  Eigen::MatrixXd at_points;  // points x modes: P_j(xi_q), coefficients -> point values
  // modes x points: M^-1 P_j'(xi_q) w_q, the volume term (F, dphi_j/dxi) per unit Jacobian
  Eigen::MatrixXd weak_derivative;
  // modes x points: M^-1 P_j(xi_q) w_q, the L2 projection of point values onto the modes
  Eigen::MatrixXd projection;
  Eigen::RowVectorXd left, right;      // P_j(-1) = (-1)^j, P_j(1) = 1
  Eigen::RowVectorXd inverse_mass;     // (2j + 1) / 2
};

// Degree p with the paper's over-integration factor 3/2: ceil(3 p / 2) points by
// default (at least p + 1; 11 for p = 7, as in the paper's table), for the flux's quadratic and A^(3/2)
// nonlinearities.
ModalBasis modal_basis(int degree, int points = 0);

}  // namespace hemotree
