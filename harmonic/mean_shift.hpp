// The periodic state's own mean: second order in the pulse.
//
// The linear periodic state (harmonic/linear_periodic.hpp) oscillates about the steady state,
// but the time-stepped periodic state's mean lies elsewhere: the 1D equations' quadratic
// terms have time averages of their own, and the junctions conserve total pressure
// p + rho u^2 / 2 where the steady state has one static pressure. In a network of large
// arteries (ADAN56) the mean pressures move by up to 1 % (140 Pa), and a run started at the
// steady mean drains the difference through its Windkessels for a cycle.
//
// Time-averaging the momentum equation of a vessel (1D model, docs/solver.md section 1),
//   d/dx <alpha Q^2 / A> + <(A / rho) dp/dx> + <(A / rho) R'(A) Q> = 0,
// about the steady state p0(x), Q0 with the linear oscillation p1, q1 (a1 = C' p1) and the
// mean's shift dp(x), dQ, to second order:
//   (A / rho)(dp' + R' dQ - kappa dp) + alpha-terms in dp (the line's D) = -N(x),
//   N = (1/rho)(C''<p1^2> p0' / 2 + C' <p1^2>' / 2) + F_A C''<p1^2> / 2 + F_AA C'^2 <p1^2> / 2
//       + F_AQ C' <p1 q1> + T',
//   T = alpha (<q1^2> / A - 2 Q0 C' <p1 q1> / A^2 + Q0^2 C'^2 <p1^2> / A^3 - Q0^2 C'' <p1^2> / (2 A^2)),
// with F(A, Q) = (A / rho) R'(A) Q the friction and its derivatives at (A, Q0), C'' = d2A/dp2.
// The shift thus obeys the line's own equation at w = 0 (harmonic/vessel_line.hpp) with a
// forcing g = (rho / A) N: along the line dp' = (tau dp - (R' / D) dQ - g / D), tau = kappa / D,
// so the forcing adds the drop G(x) = int_0^x e^{tau (x - s)} g(s) / D ds along it: the line's
// two-port with p_b + G(l) in place of p_b.
//
// At a junction the ends' total pressures are equal, so an end's static mean is the node's
// total one less its mean kinetic pressure rho <u^2> / 2, u = Q / A to second order
// (mean_kinetic_pressure). Time averages of products of harmonics: <f g> = sum_k Re(F_k G_k*) / 2.
#pragma once

#include <complex>
#include <span>
#include <vector>

#include "harmonic/vessel_line.hpp"

namespace hemotree {

// What a line needs beyond itself: the tube law's curvature and the friction's lumen.
struct LumenSlopes {
  double area_curvature = 0;       // C'' = d2A/dp2 [m^2/Pa^2]
  double resistance_slope = 0;     // dR'/dA [Pa s/m^6]
  double resistance_curvature = 0; // d2R'/dA2 [Pa s/m^8]
};

// Time averages of the pulse at a point of a line and their derivatives along it.
struct PulseMoments {
  double pp = 0, pq = 0, qq = 0;     // <p1^2>, <p1 q1>, <q1^2>
  double dpp = 0, dpq = 0, dqq = 0;  // d/dx of each
};

// The moments at x along `line` from its harmonics: omega[k], and the end pressures
// p_from[k], p_to[k] of each.
PulseMoments pulse_moments(const VesselLine& line, std::span<const double> omega, std::span<const std::complex<double>> p_from,
                           std::span<const std::complex<double>> p_to, double x);

// g(x) = (rho / A) N(x) [Pa/m]: the pressure gradient the pulse's quadratic terms add to the mean.
double mean_forcing(const VesselLine& line, const LumenSlopes& slopes, double density, const PulseMoments& m);

// rho <u^2> / 2 [Pa] with u = Q / A to second order: the mean flow's and the pulse's.
double mean_kinetic_pressure(const VesselLine& line, const LumenSlopes& slopes, double density, const PulseMoments& m);

// G(x) [Pa] at x = i l / intervals, i = 0 .. intervals: what the forcing adds to the shift's drop
// from x = 0 (trapezoids of the exact exponential weight; G(0) = 0).
std::vector<double> forcing_drops(const VesselLine& line, const LumenSlopes& slopes, double density,
                                  std::span<const double> omega, std::span<const std::complex<double>> p_from,
                                  std::span<const std::complex<double>> p_to, int intervals = 64);

// The shift along the line at the same points: dp(x) = e^{tau x} dp(0) - (R' / D) dQ (e^{tau x} - 1) / tau - G(x).
std::vector<double> mean_shift_profile(const VesselLine& line, double dp_from, double dq, std::span<const double> drops);

}  // namespace hemotree
