// The expected size of a tree before it is grown, so that a request too large for the
// machine is refused at once instead of failing after minutes.
#pragma once

#include <cstddef>

#include "generator/growth_rules.hpp"
#include "generator/tree_growth.hpp"

namespace hemotree {

// Expected number of vessels: N(D) = 1 + P(branch | D) E[N(D1) + N(D2) | branch], the
// expectation over kappa ~ U[kappa_min, kappa_max], solved on a grid in log D from D_min
// upwards (daughters are always thinner than their parent).
double expected_vessel_count(const GrowthRules& rules, const GrowthParameters& parameters);

// Bytes vgen holds per vessel at its peak (network arrays, nodes, layout, output blocks).
inline constexpr double vgen_bytes_per_vessel = 200.0;

// MemAvailable from /proc/meminfo, in bytes; 0 when unknown.
double available_memory_bytes();

}  // namespace hemotree
