// Linear Womersley waves in a rigid-to-elastic tube (the paper's section "One-dimensional
// modeling framework", eq. wavespeedWomersley): the Womersley number, Bessel functions J0
// and J1 of complex argument, and the wave number, phase velocity and attenuation of a
// harmonic of angular frequency omega.
#pragma once

#include <complex>

namespace hemotree {

// J_n(z) for n = 0 or 1 and any finite complex z. For |z| <= 20 the power series
// sum_k (-1)^k (z/2)^(2k+n) / (k! (k+n)!), summed in long double until a term falls below
// 1e-17 of the sum; beyond, Hankel's asymptotic expansion (relative error below ~1e-15 there,
// growing with |z| only through the range of double: |Im z| above ~700 overflows).
// Throws std::domain_error for n other than 0 or 1, for a non-finite z, or where the result
// would overflow.
std::complex<double> bessel_j(int n, std::complex<double> z);

// W = (D/2) sqrt(rho omega / mu). Throws InputError unless all inputs are finite and > 0.
double womersley_number(double diameter, double density, double viscosity, double omega);

struct WomersleyWave {
  double phase_velocity;              // c = omega / Re k [m/s]
  double attenuation;                 // gamma = -2 pi Im k / Re k (per wavelength)
  std::complex<double> wave_number;   // k, the root with Re k > 0 [1/m]
};

// k(omega) = (omega / c_ref) (1 / (1 - F10))^(1/2), F10 = 2 J1(i^(3/2) W) / (i^(3/2) W
// J0(i^(3/2) W)), with c_ref the elastic speed c0 = sqrt(A / rho dp/dA).
// Limits: c -> c_ref as W -> infinity; c -> W c_ref / 2 as W -> 0 (exactly, factor 1, see
// womersley.cpp), with gamma -> 2 pi. Below W = 1e-3 the small-W expansion is used.
// Any W > 0 is supported: beyond |z| = 20, F10 comes from the ratio J1/J0 of Hankel's
// expansion, which does not overflow where J0 and J1 do.
// Throws InputError unless elastic_speed, womersley and omega are finite and > 0.
WomersleyWave womersley_wave(double elastic_speed, double womersley, double omega);

}  // namespace hemotree
