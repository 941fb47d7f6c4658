#include "generator/size_estimate.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>
#include <vector>

namespace hemotree {

double expected_vessel_count(const GrowthRules& rules, const GrowthParameters& p) {
  // Grid in x = ln(D / D_min); below x = 0 a vessel never branches (N = 1), and daughters
  // sit at least ln(1/kappa_max) below their parent, which the fine step resolves.
  constexpr double step = 1e-3;
  constexpr int quadrature = 48;  // midpoint rule over kappa
  const double top = std::log(p.root_diameter / p.min_diameter);
  const auto points = static_cast<std::size_t>(std::ceil(top / step)) + 1;
  std::vector<double> count(points, 1.0);

  auto count_at = [&](double x) {
    if (x < 0) return 1.0;  // below D_min: a leaf, whatever the rule
    const double s = x / step;
    const auto k = std::min(static_cast<std::size_t>(s), points - 2);
    const double t = s - static_cast<double>(k);
    return (1 - t) * count[k] + t * count[k + 1];
  };

  for (std::size_t k = 0; k < points; ++k) {
    const double x = static_cast<double>(k) * step;
    const double d = p.min_diameter * std::exp(x);
    const BranchingRange& range = rules.range_for(std::min(d, p.root_diameter));
    double below = 0;
    for (int q = 0; q < quadrature; ++q) {
      const double kappa = range.kappa_min + (range.kappa_max - range.kappa_min) *
                                                 (q + 0.5) / quadrature;
      const Daughters ds = murray_daughters(d, kappa, range.murray_exponent);
      if (!branches(rules.stop, d, ds, p.min_diameter)) continue;
      below += count_at(std::log(ds.first / p.min_diameter)) +
               count_at(std::log(ds.second / p.min_diameter));
    }
    count[k] = 1.0 + below / quadrature;
  }
  return count_at(top);
}

double available_memory_bytes() {
  std::ifstream meminfo("/proc/meminfo");
  std::string key;
  double kib = 0;
  std::string unit;
  while (meminfo >> key >> kib >> unit)
    if (key == "MemAvailable:") return kib * 1024.0;
  return 0.0;
}

}  // namespace hemotree
