// Rescaling a tree's generation profile to a budget (docs/pruning.md, "Target profile").
//
// The full tree's profile f[g] doubles from generation to generation (binary growth), leaves
// 2^g where vessels start to stop branching, peaks and declines. The target keeps that right
// tail at a reduced level and reaches it by binary growth from the root:
//
//     t[0] = 1,   t[g] = min( 2 t[g-1],  f[g],  s E[g] ),   E[g] = max_{h >= g} f[h],
//
// with the scale s in (0, 1] chosen so that sum_g t[g] = budget. E is f seen from the right
// (its decreasing envelope): equal to f on the declining tail, flat at the peak value before
// it. Scaling f itself (t = min(2 t[g-1], s f)) cannot work: f = 2^g up to generation ~17, so
// s f would also scale the first generations (t[1] = 2 s < 2 vessels). Scaling the envelope
// instead gives the shape of the paper's Figure 4 (c): binary growth up to the generation
// where 2^g meets the scaled level s f_max (earlier than in the full tree, the smaller the
// budget), a plateau, then the full tree's own tail scaled by s, down to the same last
// generations where the capillaries are.
#include "pruner/generation_profile.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <string>

#include "core/errors.hpp"

namespace hemotree {

namespace {

// The real-valued profile for a scale s; its sum grows continuously and monotonically with s.
std::vector<double> scaled_profile(const std::vector<double>& full,
                                   const std::vector<double>& envelope, double s) {
  std::vector<double> t(full.size(), 0.0);
  t[0] = 1.0;
  for (std::size_t g = 1; g < full.size(); ++g)
    t[g] = std::min({2.0 * t[g - 1], full[g], s * envelope[g]});
  return t;
}

double sum(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0); }

// Whole sibling pairs from the real profile. Every generation g >= 1 holds an integer number
// of pairs; rounding the running sum (not each generation) keeps the total exact and moves
// each generation by less than one pair. A generation is capped by twice its parents and by
// the full tree; what a cap removes is carried to the next generations, and what is still left
// at the end goes to the generations furthest below their real value that have room.
std::vector<double> whole_pairs(const std::vector<double>& real, const std::vector<double>& full,
                                std::int64_t total_pairs) {
  const std::size_t n = real.size();
  std::vector<std::int64_t> pairs(n, 0);
  auto cap = [&](std::size_t g, std::int64_t parents) {
    return std::min<std::int64_t>(parents, static_cast<std::int64_t>(std::floor(full[g] / 2.0)));
  };
  double carry = 0.0;
  std::int64_t parents = 1, placed = 0;
  for (std::size_t g = 1; g < n; ++g) {
    const double wanted = real[g] / 2.0 + carry;
    pairs[g] = std::clamp<std::int64_t>(std::llround(wanted), 0, cap(g, parents));
    carry = wanted - static_cast<double>(pairs[g]);
    parents = 2 * pairs[g];
    placed += pairs[g];
  }
  while (placed < total_pairs) {
    std::size_t best = 0;
    double best_gap = -1e300;
    std::int64_t parents_above = 1;
    for (std::size_t g = 1; g < n; ++g) {
      const double gap = real[g] / 2.0 - static_cast<double>(pairs[g]);
      if (pairs[g] < cap(g, parents_above) && gap > best_gap) best = g, best_gap = gap;
      parents_above = 2 * pairs[g];
    }
    if (best == 0) break;  // every generation is full: the tree is smaller than the budget
    ++pairs[best];
    ++placed;
  }
  std::vector<double> t(n, 0.0);
  t[0] = 1.0;
  for (std::size_t g = 1; g < n; ++g) t[g] = 2.0 * static_cast<double>(pairs[g]);
  while (t.size() > 1 && t.back() == 0.0) t.pop_back();
  return t;
}

// A count as JSON: an integer when it is whole (the counts always are), else a number.
nlohmann::json number(double x) {
  if (x == std::floor(x) && std::abs(x) < 9e15) return static_cast<std::int64_t>(x);
  return x;
}

nlohmann::json counts(const std::vector<double>& v, std::size_t length) {
  nlohmann::json a = nlohmann::json::array();
  for (std::size_t g = 0; g < length; ++g) a.push_back(number(g < v.size() ? v[g] : 0.0));
  return a;
}

}  // namespace

std::vector<double> rescale_profile(const std::vector<double>& full, std::size_t budget) {
  if (budget == 0) throw InputError("the budget must be at least one vessel");
  if (full.empty() || full[0] != 1.0)
    throw InputError("a tree's generation profile starts with its one root vessel");
  // A full binary tree holds 1 + 2k vessels: aim at the largest such total within budget.
  const double total = static_cast<double>(budget % 2 == 1 ? budget : budget - 1);

  std::vector<double> envelope(full);
  for (std::size_t g = full.size() - 1; g-- > 0;)
    envelope[g] = std::max(envelope[g], envelope[g + 1]);
  if (sum(scaled_profile(full, envelope, 1.0)) <= total) return full;  // nothing to prune

  // sum(s) is continuous and nondecreasing, 1 at s = 0: bisect to machine precision.
  double lo = 0.0, hi = 1.0;
  for (int i = 0; i < 200 && hi - lo > 1e-15; ++i) {
    const double mid = 0.5 * (lo + hi);
    (sum(scaled_profile(full, envelope, mid)) < total ? lo : hi) = mid;
  }
  const std::vector<double> real = scaled_profile(full, envelope, hi);
  return whole_pairs(real, full, static_cast<std::int64_t>(total - 1.0) / 2);
}

nlohmann::json to_json(const ProfileReport& report) {
  const std::size_t length =
      std::max({report.full.size(), report.target.size(), report.achieved.size()});
  nlohmann::json generation = nlohmann::json::array();
  for (std::size_t g = 0; g < length; ++g) generation.push_back(g);
  return {{"generation", generation},
          {"full", counts(report.full, length)},
          {"target", counts(report.target, length)},
          {"achieved", counts(report.achieved, length)},
          {"total",
           {{"full", number(sum(report.full))},
            {"target", number(sum(report.target))},
            {"achieved", number(sum(report.achieved))}}}};
}

}  // namespace hemotree
