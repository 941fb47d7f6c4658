// A tree grown in code by vgen's rules for the tests that need a realistic one (partition,
// distributed solves): D_root 150 um to D_min 7 um, about 16,500 vessels, in milliseconds.
#pragma once

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <random>
#include <utility>
#include <vector>

#include "formats/boundary_conditions.hpp"
#include "formats/network.hpp"
#include "generator/growth_rules.hpp"
#include "generator/tree_growth.hpp"

namespace hemotree::test_networks {

// vgen --root-diameter ROOT --min-diameter MIN --seed SEED, in code.
inline Network grown_tree(double root_diameter, double min_diameter, std::uint64_t seed = GrowthParameters{}.seed) {
  GrowthParameters p;
  p.root_diameter = root_diameter;
  p.min_diameter = min_diameter;
  p.seed = seed;
  return grow_tree(default_rules(), p);
}

inline Network grown_tree() { return grown_tree(150e-6, 7e-6); }

// A network's vessels (from, to) with its nodes labelled in a shuffled order (seed), and every
// `reversed`-th vessel the other way round (0: none): a forest whose labels no longer hang
// every node from a lower one.
struct Edges {
  std::vector<std::int32_t> a, b;
};
inline Edges shuffled_edges(const Network& net, unsigned seed, std::size_t reversed = 0) {
  std::vector<std::int32_t> relabel(net.node_count());
  std::iota(relabel.begin(), relabel.end(), 0);
  std::shuffle(relabel.begin(), relabel.end(), std::mt19937(seed));
  Edges e{std::vector<std::int32_t>(net.vessel_count()), std::vector<std::int32_t>(net.vessel_count())};
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    e.a[v] = relabel[static_cast<std::size_t>(net.from[v])];
    e.b[v] = relabel[static_cast<std::size_t>(net.to[v])];
    if (reversed > 0 && v % reversed == 0) std::swap(e.a[v], e.b[v]);
  }
  return e;
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

// The grown tree fed at its root by `inflow` into outlets of the given type at its leaves.
inline Network fed_tree(BoundaryType outlets, const Waveform& inflow) {
  Network net = grown_tree();
  add_leaf_outlets(net, outlets);
  net.inlet = Inlet{net.id[0], inflow};
  return net;
}

}  // namespace hemotree::test_networks
