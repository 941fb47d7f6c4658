// Stochastic growth of a full binary vascular tree (the paper's "Stochastic growth model").
#pragma once

#include <cstdint>
#include <functional>

#include "core/uniform_source.hpp"  // the tree's random draws
#include "formats/network.hpp"
#include "generator/growth_rules.hpp"

namespace hemotree {

struct GrowthParameters {
  double root_diameter = 1e-3;  // [m]
  double min_diameter = 7e-6;   // [m]
  std::uint64_t seed = 1;
};

// The most vessels a grown tree may have: node and vessel indices are 32-bit, and a tree of
// n vessels has n + 1 nodes.
inline constexpr std::size_t max_grown_vessels = 2'147'483'646;

// Grows the tree breadth first from a root vessel of root_diameter: every vessel draws
// kappa from its diameter's range and splits by Murray's law, until the stop rule ends the
// branch. Vessel ids are the breadth-first order (root 0); the node at the distal end of
// vessel i has id i + 1, the inlet node id 0. No coordinates (see tree_layout.hpp).
// progress(done) is called now and then with the number of vessels made. InputError when the
// tree would exceed max_grown_vessels.
Network grow_tree(const GrowthRules& rules, const GrowthParameters& parameters,
                  std::size_t expected_vessels = 0,
                  const std::function<void(std::size_t)>& progress = {});

// Daughter diameters of a parent by Murray's law D_p^m = D_1^m + D_2^m with D_1 = kappa D_p.
struct Daughters {
  double first, second;
};
Daughters murray_daughters(double parent, double kappa, double m);

// Whether a parent with these daughters branches under the stop rule.
bool branches(StopRule rule, double parent, Daughters daughters, double min_diameter);

double draw_length(const LengthLaw& law, double diameter, UniformSource& uniform);

}  // namespace hemotree
