#include "pulse/degree_choice.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "pulse/stability_limit.hpp"

namespace hemotree {

double linear_profile_error(const TubeLaw& law, const ViscosityTable& viscosity, double p_in, double p_out) {
  const double mean = 0.5 * (p_in + p_out);
  if (p_in == p_out || mean <= 0) return 0;
  auto gradient = [&](double p) {
    const double a = law.area(p);
    return viscosity(a) / (a * a);
  };
  return std::abs(p_in - p_out) * std::abs(std::log(gradient(p_out) / gradient(p_in))) / mean;
}

std::vector<int> choose_degrees(std::span<const double> element_transit, std::span<const double> linear_error,
                                double period, const DegreeRule& rule, TimeScheme scheme) {
  auto limit = [&](int p) { return courant_limit(p, scheme); };
  const std::size_t n = element_transit.size();
  std::vector<int> degree(n);
  // The shortest wavelength is c T / harmonics, so h / wavelength = transit harmonics / T.
  const double shortest_period = period / rule.harmonics;
  const int curved = std::min(2, rule.high);  // the degree of a short vessel too curved for a line
  double step = std::numeric_limits<double>::infinity();
  for (std::size_t v = 0; v < n; ++v) {
    degree[v] = element_transit[v] < rule.short_vessel * shortest_period ? rule.low : rule.high;
    if (degree[v] < curved && !linear_error.empty() && linear_error[v] > rule.linear_error) degree[v] = curved;
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
