// The polynomial degree of each vessel, chosen automatically (hemosolve's default,
// `--degree auto`). Three observations decide it (docs/solver.md, "Degrees per vessel"):
// - In a vessel much shorter than the shortest wavelength of the pulse, p and Q are nearly
//   linear along it: a low degree represents them. Elsewhere (large arteries) the full degree
//   is needed to carry the waves.
// - Nearly linear is not always linear enough: where the pressure drop narrows the lumen
//   along the vessel, the friction gradient k mu Q / A^2 steepens, and the pressure profile
//   bends. In the narrowest capillaries a linear profile then misses the pulsatility at the
//   vessel's centre by up to 10 %; such vessels take degree 2.
// - One time step serves the whole network, bounded by the vessel with the smallest
//   (element length / wave speed) at its degree. Every other vessel may take the highest
//   degree whose own bound still allows that step: accuracy at no cost in steps.
#pragma once

#include <span>
#include <vector>

#include "physics/viscosity_table.hpp"
#include "pulse/time_scheme.hpp"
#include "physics/tube_law.hpp"

namespace hemotree {

struct DegreeRule {
  int low = 1;              // the degree of acoustically short vessels
  int high = 7;             // the degree of the others
  int raise_to = 2;         // the most a short vessel is raised to when the step allows it
  double short_vessel = 0.05;  // element length / shortest wavelength below which a vessel is short
  int harmonics = 25;       // the shortest wavelength is that of this harmonic of the pulse
  // The largest linear_profile_error at which a short vessel may stay linear (degree 1).
  // Measured against p = 7 on the 1001-vessel network: a linear vessel's pulsatility index
  // is off by 0.6-1.1 times the estimate (above 1 %), its mean pressure by a tenth of it.
  double linear_error = 0.01;
};

// How far a linear profile is from a vessel's steady one, relative to its pressure, when
// the steady flow drops the pressure from p_in to p_out: |p_in - p_out| |ln(g_out / g_in)|
// / ((p_in + p_out) / 2) with g = mu(A) / A^2 the friction gradient per unit flow at each
// end's area. Zero in a rigid vessel or one without flow; about 0.1 in a 5.6 um capillary
// with a 1000 Pa drop (dA/A = 6 %, Pries viscosity).
double linear_profile_error(const TubeLaw& law, const ViscosityTable& viscosity, double p_in, double p_out);

// element_transit: h / c per vessel (element length over wave speed) [s]; linear_error:
// linear_profile_error per vessel, or empty where the network has no steady flow (then no
// vessel is raised for it); period: the pulse's [s].
std::vector<int> choose_degrees(std::span<const double> element_transit, std::span<const double> linear_error,
                                double period, const DegreeRule& rule, TimeScheme scheme);

}  // namespace hemotree
