// The per-generation vessel count of a tree and its rescaling to a budget (the paper's
// "Truncation strategy", Figure 4 (c)): the full tree's profile grows as 2^g, leaves that
// exponential near generation 17 and declines; the target keeps that smooth shape at a
// smaller total, leaving 2^g earlier, with its right tail still reaching the generations
// where capillaries appear.
#pragma once

#include <cstddef>
#include <vector>

#include <nlohmann/json.hpp>

namespace hemotree {

struct ProfileReport {
  std::vector<double> full;      // vessels per generation in the full tree
  std::vector<double> target;    // the rescaled profile (whole numbers, held as doubles)
  std::vector<double> achieved;  // vessels per generation kept
};
// {"generation": [0, 1, ...], "full": [...], "target": [...], "achieved": [...],
//  "total": {"full": N, "target": N, "achieved": N}}: the three lists padded with zeros to
// the same length, whole counts written as integers (scripts/plot-pruning-profile reads it).
nlohmann::json to_json(const ProfileReport& report);

// Rescales a full binary tree's generation profile to a total of budget vessels:
//   t[0] = 1,  t[g] = min(2 t[g-1], full[g], s E[g]),  E[g] = max over h >= g of full[h],
// with the scale s found by bisection, then rounded to whole sibling pairs (docs/pruning.md).
// Binary growth from the root until it meets the level s max(full), level to the full
// tree's peak, then the full tree's own declining tail scaled by s, down to the same last
// generations. The result satisfies
// t[0] = 1, t[g] <= full[g], t[g] <= 2 t[g-1] (a generation cannot hold more than twice
// its parents), t[g] even for g >= 1 (whole pairs; where full[g] is odd, at most full[g] - 1)
// and sums to the largest odd number <= budget (a full binary tree holds 1 + 2k vessels); a
// budget at least the full tree's total returns full. Trailing zero generations are dropped.
// InputError for a zero budget or a profile that does not start with one root vessel.
std::vector<double> rescale_profile(const std::vector<double>& full, std::size_t budget);

}  // namespace hemotree
