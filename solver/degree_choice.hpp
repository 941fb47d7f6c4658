// The polynomial degree of each vessel, chosen automatically (hemosolve's default,
// `--degree auto`). Two observations decide it (docs/solver.md, "Degrees per vessel"):
// - In a vessel much shorter than the shortest wavelength of the pulse, p and Q are nearly
//   linear along it: a low degree represents them. Elsewhere (large arteries) the full degree
//   is needed to carry the waves.
// - One time step serves the whole network, bounded by the vessel with the smallest
//   (element length / wave speed) at its degree. Every other vessel may take the highest
//   degree whose own bound still allows that step: accuracy at no cost in steps.
#pragma once

#include <span>
#include <vector>

#include "solver/time_scheme.hpp"

namespace hemotree {

struct DegreeRule {
  int low = 1;              // the degree of acoustically short vessels
  int high = 7;             // the degree of the others
  int raise_to = 2;         // the most a short vessel is raised to when the step allows it
  double short_vessel = 0.05;  // element length / shortest wavelength below which a vessel is short
  int harmonics = 25;       // the shortest wavelength is that of this harmonic of the pulse
};

// element_transit: h / c per vessel (element length over wave speed) [s]; period: the
// pulse's [s].
std::vector<int> choose_degrees(std::span<const double> element_transit, double period,
                                const DegreeRule& rule, TimeScheme scheme);

}  // namespace hemotree
