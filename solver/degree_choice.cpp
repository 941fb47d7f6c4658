#include "solver/degree_choice.hpp"

#include <algorithm>
#include <limits>

#include "solver/stability_limit.hpp"

namespace hemotree {

std::vector<int> choose_degrees(std::span<const double> element_transit, double period,
                                const DegreeRule& rule, TimeScheme scheme) {
  auto limit = [&](int p) { return courant_limit(p, scheme); };
  const std::size_t n = element_transit.size();
  std::vector<int> degree(n);
  // The shortest wavelength is c T / harmonics, so h / wavelength = transit harmonics / T.
  const double shortest_period = period / rule.harmonics;
  double step = std::numeric_limits<double>::infinity();
  for (std::size_t v = 0; v < n; ++v) {
    degree[v] = element_transit[v] < rule.short_vessel * shortest_period ? rule.low : rule.high;
    step = std::min(step, limit(degree[v]) * element_transit[v]);
  }
  // Raise short vessels while their own bound stays 10 % above the network's step, so that
  // the pressure and flow of the run (which change the wave speed a little) don't make them
  // the limit.
  for (std::size_t v = 0; v < n; ++v)
    for (int p = degree[v] + 1; p <= rule.raise_to; ++p)
      if (limit(p) * element_transit[v] >= 1.1 * step) degree[v] = p;
  return degree;
}

}  // namespace hemotree
