// A vessel as a uniform transmission line about its loaded state: the 1D equations
// linearised about a lumen A and a mean velocity U (the steady state's, at the vessel's mean
// pressure) for small oscillations of angular frequency w, x(t) = Re X e^{i w t}. With
// a = C' p,
//
//   i w C' P + dQ/dx = 0,
//   i w Q + alpha d/dx (2 U Q - U^2 a) + (A / rho) dP/dx = -(k nu / A) Q,
//
//   C' = dA/dp (tube law),  L' = rho / A,  R' = k mu(A) / A^2 (the 1D model's friction,
//   k = 2 pi alpha / (alpha - 1)),  c^2 = 1 / (L' C').
// (Linearising the friction -k nu Q / A about the mean flow gives also + k nu Q_mean a / A^2,
// which the steady pressure gradient's own term (a / rho) dp_mean/dx cancels exactly.) So
// d/dx (P, Q) = M (P, Q) with
//   M = [[tau, -z / D], [-i w C', 0]],  z = R' + i w L',  D = 1 - alpha U^2 / c^2,
//   tau = 2 alpha i w U / (c^2 D),
// and the transfer from x = 0 to x is exp(M x) = e^{tau x / 2} (cosh(s x) I + sinh(s x) / s
// (M - tau / 2 I)), s^2 = tau^2 / 4 + (z / D) i w C' (Re s >= 0). At rest (U = 0) it is the
// classic line: s = gamma = sqrt(z i w C'), Z_c = z / gamma (Womersley 1957; Milnor,
// Hemodynamics, ch. 8). A mean flow makes it non-reciprocal: waves run at c +- U (to first
// order in U / c), which in a large artery (U / c ~ 0.05-0.1) shifts the pulse by as much as
// the equations' nonlinear terms do.
//
// As a two-port between its nodes (network_flow/harmonic_system.hpp): the flows it draws out
// of its `from` node (Q(0)) and its `to` node (-Q(l)),
//   Y_aa = -(s coth(s l) + tau / 2) / m,   Y_ab = s csch(s l) / (E m),
//   Y_ba = E s csch(s l) / m,              Y_bb = -(s coth(s l) - tau / 2) / m,
// m = -z / D, E = e^{tau l / 2} (of modulus 1: tau is imaginary). Where |s l| is small (a vessel
// the pulse crosses in phase: the run's 0D vessels) this is the vessel's R + i w L in series
// with i w C / 2 at each end, the 0D vessel's own pi circuit.
#pragma once

#include <array>
#include <complex>

#include "network_flow/harmonic_system.hpp"

namespace hemotree {

struct VesselLine {
  using Complex = std::complex<double>;
  double resistance = 0;     // R' [Pa s/m^4]
  double inertance = 0;      // L' [kg/m^5]
  double compliance = 0;     // C' [m^3/(Pa m)] = dA/dp
  double length = 0;         // l [m]
  double mean_velocity = 0;  // U [m/s], from -> to
  double alpha = 4.0 / 3.0;  // momentum-flux factor

  struct Matrix {
    Complex tau, m12, m21, s;  // M's entries (M_11 = tau, M_22 = 0) and s
  };
  Matrix matrix(double w) const {
    const double uc2 = mean_velocity * mean_velocity * inertance * compliance;  // U^2 / c^2
    const double d = 1 - alpha * uc2;
    const Complex tau(0, 2 * alpha * w * mean_velocity * inertance * compliance / d);
    const Complex m12 = -Complex(resistance, w * inertance) / d, m21(0, -w * compliance);
    Complex s = std::sqrt(0.25 * tau * tau + m12 * m21);
    if (s.real() < 0) s = -s;
    return {tau, m12, m21, s};
  }
  // At rest (U = 0): the propagation constant gamma and the characteristic impedance.
  Complex propagation(double w) const { return matrix(w).s; }
  Complex characteristic_impedance(double w) const { return Complex(resistance, w * inertance) / propagation(w); }

  TwoPort two_port(double w) const {
    const Matrix m = matrix(w);
    const Complex sl = m.s * length, e = std::exp(0.5 * m.tau * length);
    Complex coth, csch;
    if (sl.real() < 20) {
      const Complex sinh = std::sinh(sl);
      coth = std::cosh(sl) / sinh;
      csch = 1.0 / sinh;
    } else {
      const Complex q = std::exp(-2.0 * sl);
      coth = (1.0 + q) / (1.0 - q);
      csch = 2.0 * std::exp(-sl) / (1.0 - q);
    }
    return {-(m.s * coth + 0.5 * m.tau) / m.m12, m.s * csch / (e * m.m12), e * m.s * csch / m.m12,
            -(m.s * coth - 0.5 * m.tau) / m.m12};
  }

  // Pressure and flow (from -> to) at x along the vessel, given its end pressures; carried
  // from the nearer end, so that a long lossy line's growing and decaying waves stay within
  // half the line's attenuation of each other.
  Complex pressure(double w, Complex p0, Complex p1, double x) const { return at(w, p0, p1, {x})[0].pressure; }
  Complex flow(double w, Complex p0, Complex p1, double x) const { return at(w, p0, p1, {x})[0].flow; }

  struct Point {
    Complex pressure, flow;
  };
  // At its start, middle and end at once (one evaluation of the line's coefficients).
  std::array<Point, 3> ends_and_middle(double w, Complex p0, Complex p1) const {
    const auto points = at(w, p0, p1, {0.0, 0.5 * length, length});
    return {points[0], points[1], points[2]};
  }

 private:
  template <std::size_t N>
  std::array<Point, N> at(double w, Complex p0, Complex p1, const double (&xs)[N]) const {
    const Matrix m = matrix(w);
    const TwoPort y = two_port(w);
    const Complex q0 = y.aa * p0 + y.ab * p1, q1 = -(y.ba * p0 + y.bb * p1);
    std::array<Point, N> out;
    for (std::size_t i = 0; i < N; ++i) {
      // From x0 = 0 with (P0, Q(0)), or from x0 = l with (P1, Q(l)).
      const bool from_start = xs[i] <= 0.5 * length;
      const double dx = from_start ? xs[i] : xs[i] - length;
      const Complex p = from_start ? p0 : p1, q = from_start ? q0 : q1;
      const Complex sx = m.s * dx, e = std::exp(0.5 * m.tau * dx);
      const Complex ch = std::cosh(sx), sh_over_s = std::abs(sx) < 1e-8 ? Complex(dx) : std::sinh(sx) / m.s;
      out[i] = {e * (ch * p + sh_over_s * (0.5 * m.tau * p + m.m12 * q)),
                e * (ch * q + sh_over_s * (m.m21 * p - 0.5 * m.tau * q))};
    }
    return out;
  }
};

}  // namespace hemotree
