// A tree grown in code by vgen's rules for the tests that need a realistic one (partition,
// distributed solves): D_root 150 um to D_min 7 um, about 16,500 vessels, in milliseconds.
#pragma once

#include "formats/network.hpp"
#include "generator/growth_rules.hpp"
#include "generator/tree_growth.hpp"

namespace hemotree::test_networks {

inline Network grown_tree() {
  GrowthParameters p;
  p.root_diameter = 150e-6;
  p.min_diameter = 7e-6;
  return grow_tree(default_rules(), p);
}

}  // namespace hemotree::test_networks
