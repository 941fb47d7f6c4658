// A vessel as a uniform transmission line about its loaded state: the 1D equations
// linearised about a lumen A (the tube law at the vessel's mean pressure) and small
// oscillations of angular frequency w, x(t) = Re X e^{i w t}:
//
//   i w C' P = -dQ/dx,   i w L' Q + R' Q = -dP/dx,
//   C' = dA/dp (tube law),  L' = rho / A,  R' = k mu(A) / A^2 (the 1D model's friction,
//   k = 2 pi alpha / (alpha - 1): the same viscous loss the time-stepped model has).
//
// With z = R' + i w L' and y = i w C': gamma = sqrt(z y) (Re gamma >= 0) and Z_c = z / gamma.
// Given the end pressures P_0 (x = 0) and P_1 (x = l):
//   P(x) = (P_0 sinh(gamma (l - x)) + P_1 sinh(gamma x)) / sinh(gamma l)
//   Q(x) = (P_0 cosh(gamma (l - x)) - P_1 cosh(gamma x)) / (Z_c sinh(gamma l))
// and, as a pi circuit between its nodes, a series admittance 1 / (Z_c sinh(gamma l)) and a
// shunt tanh(gamma l / 2) / Z_c at each end (Womersley 1957; Milnor, Hemodynamics, ch. 8).
// Where |gamma l| is small (a vessel the pulse crosses in phase: the run's 0D vessels) the
// circuit is the vessel's R + i w L in series and i w C / 2 at each end, the 0D vessel's own.
// Written with scaled exponentials where Re(gamma l) is large, so a long lossy line does not
// overflow.
#pragma once

#include <complex>

namespace hemotree {

struct VesselLine {
  using Complex = std::complex<double>;
  double resistance = 0;  // R' [Pa s/m^4]
  double inertance = 0;   // L' [kg/m^5]
  double compliance = 0;  // C' [m^3/(Pa m)] = dA/dp
  double length = 0;      // l [m]

  Complex propagation(double w) const { return std::sqrt(Complex(resistance, w * inertance) * Complex(0, w * compliance)); }
  Complex characteristic_impedance(double w) const { return Complex(resistance, w * inertance) / propagation(w); }

  struct PiCircuit {
    Complex series, shunt;  // [m^3/(Pa s)]
  };
  PiCircuit pi_circuit(double w) const {
    const Complex g = propagation(w) * length, zc = characteristic_impedance(w);
    const Complex series = g.real() < 20 ? 1.0 / (zc * std::sinh(g)) : 2.0 * std::exp(-g) / (zc * (1.0 - std::exp(-2.0 * g)));
    return {series, std::tanh(0.5 * g) / zc};
  }
  Complex pressure(double w, Complex p0, Complex p1, double x) const {
    const Complex g = propagation(w);
    return p0 * sinh_ratio(g * (length - x), g * length) + p1 * sinh_ratio(g * x, g * length);
  }
  // Q along the vessel (from x = 0 to x = l).
  Complex flow(double w, Complex p0, Complex p1, double x) const {
    const Complex g = propagation(w);
    return (p0 * cosh_ratio(g * (length - x), g * length) - p1 * cosh_ratio(g * x, g * length)) /
           characteristic_impedance(w);
  }

 private:
  // sinh(u) / sinh(v) and cosh(u) / sinh(v) for 0 <= Re u <= Re v.
  static Complex sinh_ratio(Complex u, Complex v) {
    if (v.real() < 20) return std::sinh(u) / std::sinh(v);
    return std::exp(u - v) * (1.0 - std::exp(-2.0 * u)) / (1.0 - std::exp(-2.0 * v));
  }
  static Complex cosh_ratio(Complex u, Complex v) {
    if (v.real() < 20) return std::cosh(u) / std::sinh(v);
    return std::exp(u - v) * (1.0 + std::exp(-2.0 * u)) / (1.0 - std::exp(-2.0 * v));
  }
};

}  // namespace hemotree
