// A vessel as a uniform transmission line about its loaded state: the 1D equations
// linearised about a lumen A and a mean velocity U (the steady state's, at the vessel's mean
// pressure) for small oscillations of angular frequency w, x(t) = Re X e^{i w t}. With
// a = C' p,
//
//   i w C' P + dQ/dx = 0,
//   i w Q + alpha d/dx (2 U Q - U^2 a) + (A / rho) (dP/dx + R' Q - kappa P) = 0,
//
//   C' = dA/dp (tube law),  L' = rho / A,  R'(A) = k mu(A) / A^2 (the 1D model's friction
//   -k mu Q / (rho A) = -(A / rho) R' Q, k = 2 pi alpha / (alpha - 1)),  c^2 = 1 / (L' C'),
//   kappa = -Q_mean C' dR'/dA = R' U C' (2 - A mu'(A) / mu).
// kappa is the friction's lumen: where a mean flow runs, a higher pressure widens the lumen
// and eases the mean flow's gradient -R'(A) Q_mean. (Of the momentum equation's terms in a,
// (a / rho)(dp_mean/dx + R' Q_mean) vanishes in the steady state; (A / rho)(dR'/dA) a Q_mean
// is left, first order in the pulse.) It makes a short vessel's line the linearisation of the
// 0D vessel's flow (1/l) int A^2 / (k mu) dp (pulse/lumped_vessels.hpp). So
// d/dx (P, Q) = M (P, Q) with
//   M = [[tau, -z / D], [-i w C', 0]],  z = R' + i w L',  D = 1 - alpha U^2 / c^2,
//   tau = (kappa + 2 alpha i w U / c^2) / D,
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
// m = -z / D, E = e^{tau l / 2}. Where |s l| is small (a vessel the pulse crosses in phase:
// the run's 0D vessels) this is the vessel's R + i w L in series with i w C / 2 at each end,
// the 0D vessel's own pi circuit, and kappa R l (P_a + P_b) / 2 more flow through it.
#pragma once

#include <array>
#include <cmath>
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
  double kappa = 0;          // the friction's lumen, -Q_mean C' dR'/dA [1/m]

  struct Matrix {
    Complex tau, m12, m21, s2;  // M's entries (M_11 = tau, M_22 = 0) and s^2
    Complex s() const {
      const Complex s = std::sqrt(s2);
      return s.real() < 0 ? -s : s;
    }
  };
  Matrix matrix(double w) const {
    const double uc2 = mean_velocity * mean_velocity * inertance * compliance;  // U^2 / c^2
    const double d = 1 - alpha * uc2;
    const Complex tau(kappa / d, 2 * alpha * w * mean_velocity * inertance * compliance / d);
    const Complex m12 = -Complex(resistance, w * inertance) / d, m21(0, -w * compliance);
    return {tau, m12, m21, 0.25 * tau * tau + m12 * m21};
  }
  // At rest (U = 0): the propagation constant gamma and the characteristic impedance.
  Complex propagation(double w) const { return matrix(w).s(); }
  Complex characteristic_impedance(double w) const { return Complex(resistance, w * inertance) / propagation(w); }

  TwoPort two_port(double w) const { return two_port(matrix(w)); }

  // Pressure and flow (from -> to) at x along the vessel, given its end pressures; carried
  // from the nearer end, so that a long lossy line's growing and decaying waves stay within
  // half the line's attenuation of each other.
  Complex pressure(double w, Complex p0, Complex p1, double x) const { return at(w, p0, p1, {x})[0].pressure; }
  Complex flow(double w, Complex p0, Complex p1, double x) const { return at(w, p0, p1, {x})[0].flow; }

  struct Point {
    Complex pressure, flow;
  };
  // At its start, middle and end at once. Where the series serve (|s l| <= 2), the whole
  // line's functions are the half line's doubled: cosh 2x = 2 cosh^2 x - 1,
  // sinh(2x) / 2x = sinhc(x) cosh x, e^{2a} = (e^a)^2.
  // At its middle alone: with f = e^{-tau x / 2} P, f'' = s^2 f, so f(l/2) = (f(0) + f(l)) /
  // (2 cosh(s l / 2)) and f'(l/2) = (f(l) - f(0)) / (l sinhc(s l / 2)); with E = e^{tau l / 4},
  //   P(l/2) = (E p0 + p1 / E) / (2 cosh(s l / 2)),
  //   Q(l/2) = (P' - tau P) / m12 = ((p1 / E - E p0) / (l sinhc(s l / 2)) - tau P(l/2) / 2) / m12.
  Point middle(double w, Complex p0, Complex p1) const {
    const Matrix m = matrix(w);
    const Hyperbolic half = hyperbolic(m, 0.5 * length);
    const Complex e = exponential(0.25 * m.tau * length), over_e = reciprocal(e);
    const Complex p = (e * p0 + p1 * over_e) * reciprocal(2.0 * half.cosh);
    const Complex slope = (p1 * over_e - e * p0) * reciprocal(length * half.sinhc);
    return {p, (slope - 0.5 * m.tau * p) * reciprocal(m.m12)};
  }
  std::array<Point, 3> ends_and_middle(double w, Complex p0, Complex p1) const {
    const Matrix m = matrix(w);
    if (std::norm(m.s2 * (length * length)) > 16) {
      const auto points = at(w, p0, p1, {0.0, 0.5 * length, length});
      return {points[0], points[1], points[2]};
    }
    const double dx = 0.5 * length;
    const Hyperbolic half = hyperbolic(m, dx);
    const Complex e_half = exponential(0.5 * m.tau * dx);
    const TwoPort y = two_port(m, doubled(half), e_half * e_half);
    const Complex q0 = y.aa * p0 + y.ab * p1, q1 = -(y.ba * p0 + y.bb * p1);
    return {Point{p0, q0}, along(m, half, e_half, dx, p0, q0), Point{p1, q1}};
  }

 private:
  static Complex exponential(Complex x) { return std::polar(std::exp(x.real()), x.imag()); }
  // cosh(s x) and sinh(s x) / (s x), both even in s x, from s^2: by their Taylor series
  // through (s x)^18 where |s x| <= 1 (the first term left out, (s x)^20 / 20!, is below
  // 1e-18, and no term exceeds cosh 1 = 1.54 for a sum of at least cos 1 = 0.54: rounding
  // stays within a few 1e-16); up to |s x| = 8 the same at x / 2^h, |s x| / 2^h <= 1,
  // doubled back h times; else
  // from one real exponential and one sincos. So no vessel of a tree needs a square root or
  // a transcendental function here: the pulse diffuses across a capillary (|s l| = 0.1 to 3
  // over ten harmonics on the full tree) but is far from decaying within it.
  struct Hyperbolic {
    Complex cosh, sinhc;
  };
  // At 2y from y: cosh 2y = 2 cosh^2 y - 1, sinh(2y) / 2y = sinhc(y) cosh(y).
  static Hyperbolic doubled(const Hyperbolic& h) { return {2.0 * h.cosh * h.cosh - 1.0, h.sinhc * h.cosh}; }
  static Hyperbolic hyperbolic(const Matrix& m, double x) {
    Complex x2 = m.s2 * (x * x);
    double size = std::norm(x2);  // |s x|^4
    if (size <= 4096) {
      int halvings = 0;
      for (; size > 1; size *= 1.0 / 16, ++halvings) x2 *= 0.25;
      // Horner from the highest term: 1/(2n)! and 1/(2n+1)! as ratios of their neighbours.
      Complex ch = 1.0, shc = 1.0;
      for (int n = 9; n >= 1; --n) {
        ch = 1.0 + x2 * ch * (1.0 / ((2 * n - 1) * (2 * n)));
        shc = 1.0 + x2 * shc * (1.0 / ((2 * n) * (2 * n + 1)));
      }
      Hyperbolic h{ch, shc};
      for (; halvings > 0; --halvings) h = doubled(h);
      return h;
    }
    const Complex z = m.s() * std::abs(x);
    const double grow = std::exp(z.real()), ch = 0.5 * (grow + 1 / grow), sh = 0.5 * (grow - 1 / grow);
    const double c = std::cos(z.imag()), s = std::sin(z.imag());
    return {Complex(ch * c, sh * s), Complex(sh * c, ch * s) / z};
  }

  TwoPort two_port(const Matrix& m) const {
    const Complex e = exponential(0.5 * m.tau * length);
    const Complex s2l2 = m.s2 * (length * length);
    if (std::norm(s2l2) <= 400 || m.s().real() * length < 20) return two_port(m, hyperbolic(m, length), e);
    // sinh would overflow: in e^{-2 s l}, which underflows harmlessly
    const Complex s = m.s(), sl = s * length, q = std::exp(-2.0 * sl);
    return two_port(m, s * (1.0 + q) / (1.0 - q), s * 2.0 * std::exp(-sl) / (1.0 - q), e);
  }
  // With S = sinh(s l) / (s l) and C = cosh(s l): s coth(s l) = C / (l S), s csch(s l) = 1 / (l S).
  TwoPort two_port(const Matrix& m, const Hyperbolic& whole, Complex e) const {
    const Complex s_csch = reciprocal(length * whole.sinhc);
    return two_port(m, whole.cosh * s_csch, s_csch, e);
  }
  TwoPort two_port(const Matrix& m, Complex s_coth, Complex s_csch, Complex e) const {
    const Complex over_m12 = reciprocal(m.m12);
    return {-(s_coth + 0.5 * m.tau) * over_m12, s_csch * reciprocal(e) * over_m12, e * s_csch * over_m12,
            -(s_coth - 0.5 * m.tau) * over_m12};
  }

  // exp(M dx) (P, Q): h the hyperbolic functions and e = e^{tau dx / 2} at dx.
  static Point along(const Matrix& m, const Hyperbolic& h, Complex e, double dx, Complex p, Complex q) {
    const Complex sh_over_s = dx * h.sinhc;
    return {e * (h.cosh * p + sh_over_s * (0.5 * m.tau * p + m.m12 * q)),
            e * (h.cosh * q + sh_over_s * (m.m21 * p - 0.5 * m.tau * q))};
  }

  template <std::size_t N>
  std::array<Point, N> at(double w, Complex p0, Complex p1, const double (&xs)[N]) const {
    const Matrix m = matrix(w);
    const TwoPort y = two_port(m);
    const Complex q0 = y.aa * p0 + y.ab * p1, q1 = -(y.ba * p0 + y.bb * p1);
    std::array<Point, N> out;
    for (std::size_t i = 0; i < N; ++i) {
      // From x0 = 0 with (P0, Q(0)), or from x0 = l with (P1, Q(l)).
      const bool from_start = xs[i] <= 0.5 * length;
      const double dx = from_start ? xs[i] : xs[i] - length;
      const Complex p = from_start ? p0 : p1, q = from_start ? q0 : q1;
      if (dx == 0) {
        out[i] = {p, q};
        continue;
      }
      out[i] = along(m, hyperbolic(m, dx), exponential(0.5 * m.tau * dx), dx, p, q);
    }
    return out;
  }
};

}  // namespace hemotree
