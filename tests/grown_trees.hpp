// A tree grown in code by vgen's rules for the tests that need a realistic one (partition,
// distributed solves): D_root 150 um to D_min 7 um, about 16,500 vessels, in milliseconds.
#pragma once

#include <cstdint>
#include <vector>

#include "formats/boundary_conditions.hpp"
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

// Every leaf of a tree an outlet to 10 mmHg: a resistance of 2e13 Pa s/m^3, or an RCR of
// 4e12 and 1.6e13 Pa s/m^3 about 1e-14 m^3/Pa.
inline void add_leaf_outlets(Network& net, BoundaryType type) {
  std::vector<unsigned char> has_daughter(net.node_count(), 0);
  for (std::size_t v = 0; v < net.vessel_count(); ++v) has_daughter[static_cast<std::size_t>(net.from[v])] = 1;
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    if (has_daughter[static_cast<std::size_t>(net.to[v])]) continue;
    Outlet o;
    o.vessel = static_cast<std::int32_t>(v);
    o.type = type;
    if (type == BoundaryType::rcr) {
      o.r1 = 4e12;
      o.r2 = 1.6e13;
      o.c = 1e-14;
    } else {
      o.r = 2e13;
    }
    o.p_out = 1333.2;
    net.outlets.push_back(o);
  }
}

}  // namespace hemotree::test_networks
