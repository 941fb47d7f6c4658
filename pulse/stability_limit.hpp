// How large a time step the waves allow: the largest Courant number nu = lambda dt / h at
// which every Bloch mode of the upwind DG advection operator of degree p lies in the time
// scheme's stability region. Elements coupled in a chain (several per vessel, or vessels in
// series through junctions) have this spectrum; its radius grows like (p + 1)^2.
#pragma once

#include <complex>
#include <vector>

#include "pulse/time_scheme.hpp"

namespace hemotree {

// Eigenvalues of the operator -d/dx of one element of unit length, degree p, over Bloch
// waves exp(i theta k) of the element index k (theta at `waves` points in [0, 2 pi)).
std::vector<std::complex<double>> dg_advection_spectrum(int degree, int waves = 128);

// Largest modulus of the amplification factor of one step at z = lambda dt. AB2's region
// holds none of the imaginary axis: resolved modes grow by about |z|^4 / 4 per step.
double amplification(TimeScheme scheme, std::complex<double> z);

// The tolerated growth per step: AB2 (and ETD2, which is AB2 for the waves) must allow a
// little (3e-5: round-off needs > 1e6 steps to grow 1e14, and friction and the outlets
// damp every mode of a network); RK4 none.
double growth_tolerance(TimeScheme scheme);

// The Courant number limit, to 0.2 %: 0.50 at p = 1, 0.20 / 15 at p = 7 for AB2.
double courant_limit(int degree, TimeScheme scheme);

}  // namespace hemotree
