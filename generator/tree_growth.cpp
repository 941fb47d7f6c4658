#include "generator/tree_growth.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/errors.hpp"
#include "core/setting_error.hpp"

namespace hemotree {

Daughters murray_daughters(double parent, double kappa, double m) {
  return {kappa * parent, std::pow(1.0 - std::pow(kappa, m), 1.0 / m) * parent};
}

bool branches(StopRule rule, double parent, Daughters d, double min_diameter) {
  switch (rule) {
    case StopRule::smaller_daughter: return std::min(d.first, d.second) >= min_diameter;
    case StopRule::mean_daughter: return 0.5 * (d.first + d.second) >= min_diameter;
    case StopRule::larger_daughter: return std::max(d.first, d.second) >= min_diameter;
    case StopRule::parent: return parent >= min_diameter;
  }
  return false;
}

double draw_length(const LengthLaw& law, double diameter, UniformSource& uniform) {
  if (law.kind == LengthLaw::Kind::uniform) return uniform.between(law.min, law.max);
  return law.zeta * std::pow(diameter / 2, law.gamma);  // r in metres (ERRATA.md s. 2)
}

Network grow_tree(const GrowthRules& rules, const GrowthParameters& p,
                  std::size_t expected_vessels,
                  const std::function<void(std::size_t)>& progress) {
  if (!(p.min_diameter > 0)) throw InputError("the minimum diameter must be positive");
  if (!(p.min_diameter < p.root_diameter))
    throw InputError("the minimum diameter must be below the root diameter");
  rules.range_for(p.root_diameter);  // throws if the rules do not cover the root
  rules.range_for(p.min_diameter);

  UniformSource uniform(p.seed);
  Network net;
  if (expected_vessels) net.reserve(expected_vessels, expected_vessels + 1);

  auto add = [&](std::int32_t from_node, double d, std::int32_t generation) {
    const std::int64_t id = static_cast<std::int64_t>(net.vessel_count());
    const std::int32_t to_node = net.add_node(id + 1);
    const double length = draw_length(rules.range_for(d).length, d, uniform);
    const double wall = rules.wall[static_cast<int>(classify(d))].thickness(d);
    net.add_vessel(id, from_node, to_node, length, d, wall, rules.youngs_modulus(d), generation);
  };

  add(net.add_node(0), p.root_diameter, 0);
  // Breadth first: the vessel list is the queue, daughters are appended behind it.
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    const double d = net.diameter[v];
    if (rules.stop == StopRule::parent && d < p.min_diameter) continue;
    const BranchingRange& range = rules.range_for(d);
    const double kappa = uniform.between(range.kappa_min, range.kappa_max);
    const Daughters daughters = murray_daughters(d, kappa, range.murray_exponent);
    if (!branches(rules.stop, d, daughters, p.min_diameter)) continue;
    if (net.vessel_count() + 2 > max_grown_vessels)
      throw SettingError("min_diameter", "the tree grows beyond " + std::to_string(max_grown_vessels) +
                                             " vessels, the most a network holds: raise " + placeholder("min_diameter"));
    const std::int32_t node = net.to[v];
    const std::int32_t generation = net.generation[v] + 1;
    add(node, daughters.first, generation);
    add(node, daughters.second, generation);
    if (progress && (v & 0xFFFF) == 0) progress(net.vessel_count());
  }
  return net;
}

}  // namespace hemotree
