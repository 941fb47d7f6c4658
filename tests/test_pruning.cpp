// Pruning a full tree to a budget (docs/pruning.md): the rescaled generation profile, the
// profile strategy's budget and spread over many seeds, the full-tree property of every
// strategy, the keep-subtree strategy, errors, and extraction of the kept network.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "formats/topology.hpp"
#include "generator/growth_rules.hpp"
#include "generator/tree_growth.hpp"
#include "generator/tree_layout.hpp"
#include "pruner/generation_profile.hpp"
#include "pruner/pruning_strategies.hpp"

namespace hemotree {
namespace {

// ---------------------------------------------------------------------------------------
// Helpers

double total(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0); }

std::size_t kept_count(const KeepMask& keep) {
  return static_cast<std::size_t>(std::count(keep.begin(), keep.end(), 1));
}

// The constraints rescale_profile promises: a root, whole sibling pairs, never more than
// twice the parents nor than the full tree, and the largest odd total within the budget.
void expect_valid_target(const std::vector<double>& full, const std::vector<double>& t,
                         std::size_t budget) {
  ASSERT_FALSE(t.empty());
  EXPECT_EQ(t[0], 1.0);
  ASSERT_LE(t.size(), full.size());
  for (std::size_t g = 1; g < t.size(); ++g) {
    SCOPED_TRACE("generation " + std::to_string(g));
    EXPECT_EQ(t[g], std::round(t[g]));
    EXPECT_EQ(std::fmod(t[g], 2.0), 0.0);
    EXPECT_GE(t[g], 0.0);
    EXPECT_LE(t[g], full[g]);
    EXPECT_LE(t[g], 2.0 * t[g - 1]);
  }
  const double want = std::min<double>(total(full), budget % 2 ? budget : budget - 1.0);
  EXPECT_EQ(total(t), want);
}

// The full-tree property, checked with the project's own topology: the root kept, and for
// every vessel either all of its daughters kept or none, and none unless it is kept itself.
void expect_full_tree(const Network& net, const KeepMask& keep, const Children& children,
                      std::size_t root) {
  ASSERT_EQ(keep.size(), net.vessel_count());
  EXPECT_EQ(keep[root], 1);
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    std::int64_t daughters = 0, kept = 0;
    for (std::int64_t k = children.offset[v]; k < children.offset[v + 1]; ++k) {
      ++daughters;
      kept += keep[children.index[k]];
    }
    if (!keep[v]) {
      ASSERT_EQ(kept, 0) << "daughters of pruned vessel " << net.id[v] << " kept";
    } else {
      ASSERT_TRUE(kept == 0 || kept == daughters)
          << "vessel " << net.id[v] << " keeps " << kept << " of " << daughters << " daughters";
    }
  }
}

void expect_full_tree(const Network& net, const KeepMask& keep) {
  expect_full_tree(net, keep, children_of(net), check_rooted_tree(net));
}

Network grow(double root_diameter, double min_diameter, std::uint64_t seed = 1) {
  GrowthParameters p;
  p.root_diameter = root_diameter;
  p.min_diameter = min_diameter;
  p.seed = seed;
  return grow_tree(default_rules(), p);
}

// The paper's truncation example starts from D_root = 1 mm, D_min = 8.5 um (about 1.9 M
// vessels with the default rules); grown once for the whole file.
const Network& paper_tree() {
  static const Network net = grow(1e-3, 8.5e-6);
  return net;
}

// A smaller tree of the same rules (about 155 000 vessels, 26 generations) for the tests
// that prune many times.
const Network& small_tree() {
  static const Network net = grow(400e-6, 8.5e-6);
  return net;
}

// A hand-made tree: the root (id 10) splits into 11 and 12; 11 into 13 and 14; 13 into 15
// and 16. Node ids are 100 + index, with coordinates.
Network hand_tree() {
  Network net;
  for (int i = 0; i < 8; ++i) net.add_node(100 + i, i, 2.0 * i, 3.0 * i);
  auto add = [&](std::int64_t id, int from, int to, int generation) {
    net.add_vessel(id, from, to, 1e-3, 100e-6 / (1 + generation), 1e-6, 1e5, generation);
  };
  add(10, 0, 1, 0);
  add(11, 1, 2, 1);
  add(12, 1, 3, 1);
  add(13, 2, 4, 2);
  add(14, 2, 5, 2);
  add(15, 4, 6, 3);
  add(16, 4, 7, 3);
  return net;
}

// ---------------------------------------------------------------------------------------
// The target profile

TEST(RescaleProfile, PureBinaryGrowthBecomesGrowthThenPlateauToTheLastGeneration) {
  // A complete binary tree of 13 generations: f[g] = 2^g, 8191 vessels.
  std::vector<double> full;
  for (int g = 0; g <= 12; ++g) full.push_back(std::ldexp(1.0, g));
  for (const std::size_t budget : {1u, 2u, 3u, 101u, 1000u, 1001u, 4095u, 8190u}) {
    SCOPED_TRACE("budget " + std::to_string(budget));
    const auto t = rescale_profile(full, budget);
    expect_valid_target(full, t, budget);
  }
  // The profile doubles, then stays level down to the last generation: the envelope of a
  // profile that never declines is its last value. 1001 = 255 (generations 0-7) + 5 x 149.
  const auto t = rescale_profile(full, 1001);
  ASSERT_EQ(t.size(), full.size());
  for (int g = 0; g <= 7; ++g) EXPECT_EQ(t[g], full[g]) << g;
  for (int g = 8; g <= 12; ++g) EXPECT_NEAR(t[g], 149.2, 1.3) << g;
  // The whole tree when the budget allows it.
  EXPECT_EQ(rescale_profile(full, 8191), full);
  EXPECT_EQ(rescale_profile(full, 100000), full);
}

TEST(RescaleProfile, RisingAndFallingProfileKeepsItsScaledTail) {
  // Binary growth to generation 12, a peak, then a decline like the generated trees' (each
  // generation keeping 40-90 % of the one before), all in whole sibling pairs.
  std::vector<double> full;
  for (int g = 0; g <= 12; ++g) full.push_back(std::ldexp(1.0, g));
  for (const double ratio : {1.6, 1.3, 0.9, 0.8, 0.7, 0.6, 0.5, 0.45, 0.4, 0.4})
    full.push_back(2.0 * std::round(full.back() * ratio / 2.0));
  const std::size_t peak = static_cast<std::size_t>(
      std::max_element(full.begin(), full.end()) - full.begin());
  ASSERT_EQ(peak, 14u);

  for (const std::size_t budget : {5u, 51u, 301u, 1001u, 5301u, 20000u}) {
    SCOPED_TRACE("budget " + std::to_string(budget));
    expect_valid_target(full, rescale_profile(full, budget), budget);
  }

  const auto t = rescale_profile(full, 1001);
  // It leaves 2^g earlier than the full tree ...
  std::size_t leaves = 0;
  while (leaves < t.size() && t[leaves] == std::ldexp(1.0, static_cast<int>(leaves))) ++leaves;
  EXPECT_LT(leaves, 12u);
  // ... and never rises where the full tree declines ...
  for (std::size_t g = peak + 1; g < t.size(); ++g) EXPECT_LE(t[g], t[g - 1]) << g;
  // ... down to the full tree's last generations, in proportion to the full tree there
  // (one scale s for the whole tail, up to the rounding to whole pairs).
  EXPECT_GE(t.size() + 3, full.size());
  const double s = t[peak] / full[peak];
  for (std::size_t g = peak; g < t.size(); ++g) {
    if (s * full[g] < 8.0) continue;  // a few pairs: rounding dominates
    EXPECT_NEAR(t[g] / full[g], s, 2.0 / full[g] + 0.05 * s) << g;
  }
}

TEST(RescaleProfile, RejectsAZeroBudgetAndAProfileWithoutARoot) {
  EXPECT_THROW(rescale_profile({1, 2, 4}, 0), InputError);
  EXPECT_THROW(rescale_profile({}, 10), InputError);
  EXPECT_THROW(rescale_profile({2, 4}, 10), InputError);
}

TEST(ProfileReport, JsonHasOneEntryPerGenerationAndTotals) {
  const ProfileReport report{{1, 2, 4, 6}, {1, 2, 2}, {1, 2, 2}};
  const auto j = to_json(report);
  ASSERT_EQ(j.at("generation").size(), 4u);
  EXPECT_EQ(j.at("generation")[3], 3);
  EXPECT_EQ(j.at("full")[3], 6);
  EXPECT_EQ(j.at("target")[3], 0);  // padded to the full tree's generations
  EXPECT_EQ(j.at("achieved").size(), 4u);
  EXPECT_EQ(j.at("total").at("full"), 13.0);
  EXPECT_EQ(j.at("total").at("target"), 5.0);
  EXPECT_EQ(j.at("total").at("achieved"), 5.0);
}

// ---------------------------------------------------------------------------------------
// The profile strategy

TEST(PruneByProfile, BudgetWithinOnePercentFullTreeOverThirtySeeds) {
  const Network& net = small_tree();
  const Children children = children_of(net);
  const std::size_t root = check_rooted_tree(net);
  for (const std::size_t budget : {101u, 1001u, 5301u}) {
    for (std::uint64_t seed = 1; seed <= 30; ++seed) {
      SCOPED_TRACE("budget " + std::to_string(budget) + ", seed " + std::to_string(seed));
      ProfileReport report;
      const KeepMask keep = prune_by_profile(net, budget, seed, &report);
      const double kept = static_cast<double>(kept_count(keep));
      EXPECT_LE(std::abs(kept - static_cast<double>(budget)), 0.01 * static_cast<double>(budget));
      EXPECT_EQ(total(report.achieved), kept);
      EXPECT_EQ(total(report.full), static_cast<double>(net.vessel_count()));
      expect_full_tree(net, keep, children, root);
    }
  }
}

TEST(PruneByProfile, PaperBudgetFollowsTheTargetWithCapillariesAllOverTheTree) {
  const Network& net = paper_tree();
  ProfileReport report;
  const KeepMask keep = prune_by_profile(net, 5301, 1, &report);
  EXPECT_EQ(kept_count(keep), 5301u);
  expect_full_tree(net, keep);

  // The achieved profile is the target, up to the last, sparsest generations.
  double off = 0.0;
  for (std::size_t g = 0; g < report.target.size(); ++g)
    off += std::abs(report.target[g] - (g < report.achieved.size() ? report.achieved[g] : 0.0));
  EXPECT_LT(off, 0.005 * 5301);
  // The right tail reaches the capillary generations: within 4 of the full tree's last.
  EXPECT_GE(report.achieved.size() + 4, report.full.size());

  // Capillaries are kept, and they hang below many different generation-3 vessels (there
  // are 8), not in one branch. Each vessel's generation-3 ancestor, top-down.
  const Children children = children_of(net);
  std::vector<std::int32_t> ancestor(net.vessel_count(), -1);
  std::vector<std::int32_t> order{static_cast<std::int32_t>(check_rooted_tree(net))};
  for (std::size_t k = 0; k < order.size(); ++k) {
    const std::int32_t v = order[k];
    for (std::int64_t j = children.offset[v]; j < children.offset[v + 1]; ++j) {
      const std::int32_t d = children.index[j];
      ancestor[d] = net.generation[d] == 3 ? d : ancestor[v];
      if (keep[d]) order.push_back(d);
    }
  }
  std::set<std::int32_t> branches;
  std::size_t capillaries = 0;
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    if (!keep[v] || net.vessel_class[v] != VesselClass::capillary) continue;
    ++capillaries;
    branches.insert(ancestor[v]);
  }
  EXPECT_GE(capillaries, 100u);
  EXPECT_GE(branches.size(), 6u);
}

TEST(PruneByProfile, SameSeedSameTreeOtherSeedOtherTree) {
  const Network& net = small_tree();
  EXPECT_EQ(prune_by_profile(net, 1001, 7), prune_by_profile(net, 1001, 7));
  EXPECT_NE(prune_by_profile(net, 1001, 7), prune_by_profile(net, 1001, 8));
}

TEST(PruneByProfile, TinyTreesAndBudgets) {
  const Network net = hand_tree();
  EXPECT_EQ(prune_by_profile(net, 1, 1), (KeepMask{1, 0, 0, 0, 0, 0, 0}));
  EXPECT_EQ(prune_by_profile(net, 2, 1), (KeepMask{1, 0, 0, 0, 0, 0, 0}));
  EXPECT_EQ(prune_by_profile(net, 3, 1), (KeepMask{1, 1, 1, 0, 0, 0, 0}));
  EXPECT_EQ(prune_by_profile(net, 5, 1), (KeepMask{1, 1, 1, 1, 1, 0, 0}));
  EXPECT_EQ(prune_by_profile(net, 7, 1), KeepMask(7, 1));
  EXPECT_EQ(prune_by_profile(net, 1000, 1), KeepMask(7, 1));
}

TEST(PruneByProfile, RejectsAZeroBudgetAndNetworksThatAreNotOneTree) {
  EXPECT_THROW(prune_by_profile(hand_tree(), 0, 1), InputError);
  Network two_roots = hand_tree();
  two_roots.add_node(200, 0, 0, 0);
  two_roots.add_node(201, 0, 0, 0);
  two_roots.add_vessel(99, 8, 9, 1e-3, 1e-5, 1e-6, 1e5, 0);
  EXPECT_THROW(prune_by_profile(two_roots, 5, 1), InputError);
  EXPECT_THROW(prune_by_diameter(two_roots, 1e-5), InputError);
  EXPECT_THROW(prune_by_profile(Network{}, 5, 1), InputError);
}

// ---------------------------------------------------------------------------------------
// The other strategies

TEST(PruneByDiameter, KeepsTheDaughtersOfEveryKeptVesselAtLeastTheCutoff) {
  const Network& net = small_tree();
  const Children children = children_of(net);
  const std::size_t root = check_rooted_tree(net);
  for (const double cutoff : {20e-6, 50e-6, 150e-6, 1.0}) {
    SCOPED_TRACE("cutoff " + std::to_string(cutoff));
    const KeepMask keep = prune_by_diameter(net, cutoff);
    expect_full_tree(net, keep, children, root);
    // Exactly the rule: a vessel is kept iff it is the root or its parent is kept with a
    // diameter >= cutoff. Murray daughters are thinner than their parent, so that is every
    // vessel whose parent is at least the cutoff.
    std::size_t expected = 1;
    for (std::size_t v = 0; v < net.vessel_count(); ++v)
      for (std::int64_t k = children.offset[v]; k < children.offset[v + 1]; ++k) {
        const bool rule = keep[v] && net.diameter[v] >= cutoff;
        ASSERT_EQ(keep[children.index[k]], rule ? 1 : 0);
        expected += net.diameter[v] >= cutoff;
      }
    EXPECT_EQ(kept_count(keep), expected);
  }
  EXPECT_EQ(kept_count(prune_by_diameter(net, 1.0)), 1u);   // the root alone
  EXPECT_EQ(kept_count(prune_by_diameter(net, 0.0)), net.vessel_count());
}

TEST(PruneByGeneration, KeepsGenerationsZeroToG) {
  const Network& net = small_tree();
  const Children children = children_of(net);
  const std::size_t root = check_rooted_tree(net);
  for (const int last : {0, 1, 5, 12, 100}) {
    SCOPED_TRACE("last generation " + std::to_string(last));
    const KeepMask keep = prune_by_generation(net, last);
    expect_full_tree(net, keep, children, root);
    for (std::size_t v = 0; v < net.vessel_count(); ++v)
      ASSERT_EQ(keep[v], net.generation[v] <= last ? 1 : 0) << v;
  }
  EXPECT_THROW(prune_by_generation(net, -1), InputError);
}

// A vessel of the given generation whose subtree holds between lo and hi vessels.
std::size_t vessel_with_subtree(const Network& net, const Children& children, int generation,
                                std::size_t lo, std::size_t hi) {
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    if (net.generation[v] != generation) continue;
    std::vector<std::int32_t> stack{static_cast<std::int32_t>(v)};
    std::size_t size = 0;
    while (!stack.empty()) {
      const std::int32_t u = stack.back();
      stack.pop_back();
      ++size;
      for (std::int64_t k = children.offset[u]; k < children.offset[u + 1]; ++k)
        stack.push_back(children.index[k]);
    }
    if (size >= lo && size <= hi) return v;
  }
  return net.vessel_count();
}

TEST(PruneKeepingSubtree, KeepsTheSubtreeThePathToItAndTrimsTheRestToTheBudget) {
  const Network& net = small_tree();
  const Children children = children_of(net);
  const std::size_t root = check_rooted_tree(net);
  const std::size_t top = vessel_with_subtree(net, children, 9, 300, 2000);
  ASSERT_LT(top, net.vessel_count());

  for (const std::size_t budget : {2001u, 5301u}) {
    SCOPED_TRACE("budget " + std::to_string(budget));
    ProfileReport report;
    const KeepMask keep = prune_keeping_subtree(net, net.id[top], budget, 3, &report);
    expect_full_tree(net, keep, children, root);
    const double kept = static_cast<double>(kept_count(keep));
    EXPECT_LE(std::abs(kept - static_cast<double>(budget)), 0.01 * static_cast<double>(budget));
    EXPECT_EQ(total(report.achieved), kept);

    // The whole subtree ...
    std::vector<std::int32_t> stack{static_cast<std::int32_t>(top)};
    while (!stack.empty()) {
      const std::int32_t u = stack.back();
      stack.pop_back();
      ASSERT_EQ(keep[u], 1) << "vessel " << net.id[u] << " of the subtree pruned";
      for (std::int64_t k = children.offset[u]; k < children.offset[u + 1]; ++k)
        stack.push_back(children.index[k]);
    }
    // ... and the path to it with its siblings: every vessel entering the path's nodes is
    // kept, and so are the others leaving them (full tree property, checked above).
    std::vector<std::int32_t> entering(net.node_count(), -1);
    for (std::size_t v = 0; v < net.vessel_count(); ++v)
      entering[net.to[v]] = static_cast<std::int32_t>(v);
    for (std::int32_t v = static_cast<std::int32_t>(top); v >= 0; v = entering[net.from[v]])
      EXPECT_EQ(keep[v], 1);
  }
}

TEST(PruneKeepingSubtree, RejectsUnknownIdsSubtreesOverTheBudgetAndAZeroBudget) {
  const Network& net = small_tree();
  EXPECT_THROW(prune_keeping_subtree(net, -12345, 1001, 1), InputError);
  // The root's subtree is the whole tree.
  EXPECT_THROW(prune_keeping_subtree(net, net.id[check_rooted_tree(net)], 1001, 1), InputError);
  EXPECT_THROW(prune_keeping_subtree(net, net.id[5], 0, 1), InputError);
  const Network tiny = hand_tree();
  EXPECT_EQ(prune_keeping_subtree(tiny, 10, 7, 1), KeepMask(7, 1));
  EXPECT_EQ(prune_keeping_subtree(tiny, 12, 3, 1), (KeepMask{1, 1, 1, 0, 0, 0, 0}));
  // Vessel 13: the path 10, 11 + 12, 13 + 14, and 15 + 16 below it.
  EXPECT_EQ(prune_keeping_subtree(tiny, 13, 7, 1), KeepMask(7, 1));
  EXPECT_THROW(prune_keeping_subtree(tiny, 13, 6, 1), InputError);
}

// ---------------------------------------------------------------------------------------
// Extraction

TEST(Extract, KeepsIdsNodeIdsCoordinatesAndMetadataAndGivesARootedTree) {
  Network net = grow(300e-6, 8.5e-6);
  lay_out_tree(net);
  ASSERT_TRUE(net.has_coordinates());
  net.extra["unknown_member"] = {{"kept", true}};
  net.blood = Blood{};
  net.blood->hematocrit = 0.4;
  net.inlet = Inlet{};
  net.outlets.push_back(Outlet{});
  net.outlets.back().vessel = static_cast<std::int32_t>(net.vessel_count() - 1);
  net.beta.assign(net.vessel_count(), 0.0);
  for (std::size_t v = 0; v < net.vessel_count(); ++v) net.beta[v] = 1e6 + static_cast<double>(v);
  const KeepMask keep = prune_by_profile(net, 1001, 5);

  const Network out = extract(net, keep);
  ASSERT_EQ(out.vessel_count(), kept_count(keep));
  EXPECT_EQ(out.id[check_rooted_tree(out)], net.id[check_rooted_tree(net)]);
  std::size_t k = 0;
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    if (!keep[v]) continue;
    ASSERT_EQ(out.id[k], net.id[v]);  // original order and ids
    EXPECT_EQ(out.node_id[out.from[k]], net.node_id[net.from[v]]);
    EXPECT_EQ(out.node_id[out.to[k]], net.node_id[net.to[v]]);
    EXPECT_EQ(out.x[out.to[k]], net.x[net.to[v]]);
    EXPECT_EQ(out.z[out.to[k]], net.z[net.to[v]]);
    EXPECT_EQ(out.diameter[k], net.diameter[v]);
    EXPECT_EQ(out.length[k], net.length[v]);
    EXPECT_EQ(out.wall_thickness[k], net.wall_thickness[v]);
    EXPECT_EQ(out.youngs_modulus[k], net.youngs_modulus[v]);
    EXPECT_EQ(out.generation[k], net.generation[v]);
    EXPECT_EQ(out.vessel_class[k], net.vessel_class[v]);
    EXPECT_EQ(out.beta[k], net.beta[v]);
    ++k;
  }
  // Every node of the extract is used; a tree of k vessels has k + 1 nodes.
  EXPECT_EQ(out.node_count(), out.vessel_count() + 1);
  EXPECT_EQ(out.x.size(), out.node_count());
  EXPECT_EQ(out.provenance, net.provenance);
  EXPECT_EQ(out.extra, net.extra);
  ASSERT_TRUE(out.blood.has_value());
  EXPECT_EQ(out.blood->hematocrit, 0.4);
  EXPECT_FALSE(out.inlet.has_value());  // boundary conditions are the pruner's to set anew
  EXPECT_TRUE(out.outlets.empty());
  EXPECT_TRUE(out.reference_pressure.empty());
  EXPECT_EQ(generations_from_inlets(out), out.generation);

  // Without coordinates, and the whole tree.
  const Network bare = hand_tree();
  Network plain;
  for (const auto id : bare.node_id) plain.add_node(id);
  plain.id = bare.id, plain.from = bare.from, plain.to = bare.to, plain.length = bare.length;
  plain.diameter = bare.diameter, plain.wall_thickness = bare.wall_thickness;
  plain.youngs_modulus = bare.youngs_modulus, plain.generation = bare.generation;
  plain.vessel_class = bare.vessel_class;
  const Network all = extract(plain, KeepMask(7, 1));
  EXPECT_FALSE(all.has_coordinates());
  EXPECT_EQ(all.id, plain.id);
  EXPECT_EQ(all.node_id, plain.node_id);
  EXPECT_THROW(extract(plain, KeepMask(3, 1)), std::invalid_argument);
}

}  // namespace
}  // namespace hemotree
