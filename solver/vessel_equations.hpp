// The 1D model of one vessel in conservative form, U = (A, Q):
//   dA/dt + dQ/dx = 0
//   dQ/dt + d/dx(alpha Q^2/A + beta A^(3/2) / (3 rho)) = -k mu Q / (rho A),  k = 2 pi alpha/(alpha - 1)
// with the tube law p = p_ref + beta (sqrt(A) - sqrt(A_ref)) (beta, A_ref constant along the
// vessel, so (A/rho) dp/dx is the x-derivative of beta A^(3/2)/(3 rho)). It is the paper's
// system (eq. govEq) with Q = A u: smooth solutions are the same, and in (A, Q) the system is a
// conservation law for any alpha, so mass is conserved exactly at every interface.
#pragma once

#include <cmath>

namespace hemotree {

// What a vessel's equations need to know about it.
struct VesselLaw {
  double beta = 0;            // [Pa/m]
  double reference_area = 0;  // [m^2]
  double reference_pressure = 0;
  double density = 0;
  double alpha = 4.0 / 3.0;

  double pressure(double a) const { return reference_pressure + beta * (std::sqrt(a) - std::sqrt(reference_area)); }
  // The area at which the tube law gives pressure p.
  double area(double p) const {
    const double s = std::sqrt(reference_area) + (p - reference_pressure) / beta;
    return s * s;
  }
  double wave_speed(double a) const { return std::sqrt(beta * std::sqrt(a) / (2 * density)); }
  double flux_area(double, double q) const { return q; }
  double flux_flow(double a, double q) const {
    return alpha * q * q / a + beta * a * std::sqrt(a) / (3 * density);
  }
  // Characteristic speeds lambda = alpha u +- sqrt(c^2 + alpha (alpha - 1) u^2).
  double lambda_forward(double a, double q) const {
    const double u = q / a, c = wave_speed(a);
    return alpha * u + std::sqrt(c * c + alpha * (alpha - 1) * u * u);
  }
  double lambda_backward(double a, double q) const {
    const double u = q / a, c = wave_speed(a);
    return alpha * u - std::sqrt(c * c + alpha * (alpha - 1) * u * u);
  }
  double total_pressure(double a, double q) const {
    const double u = q / a;
    return pressure(a) + 0.5 * density * u * u;
  }
};

// The friction coefficient k = 2 pi alpha/(alpha - 1): friction -k mu Q / A per unit length
// (8 pi mu u A / A for the parabolic profile, alpha = 4/3).
inline double friction_coefficient(double alpha) {
  constexpr double pi = 3.14159265358979323846;
  return 2 * pi * alpha / (alpha - 1);
}

}  // namespace hemotree
