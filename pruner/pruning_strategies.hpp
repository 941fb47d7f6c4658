// Ways to cut a full tree to a computational budget (docs/pruning.md). Each returns a keep
// mask over the vessels of the full tree that is again a full tree: the root is kept, a kept
// vessel's parent is kept, and at every junction either all daughters are kept or none.
// Generations are counted by topology from the root (equal to the stored `generation` in
// the trees vgen grows). Each throws InputError when the network is not one rooted tree.
#pragma once

#include <cstdint>
#include <vector>

#include "formats/network.hpp"
#include "pruner/generation_profile.hpp"

namespace hemotree {

using KeepMask = std::vector<std::uint8_t>;  // 1 = kept, one entry per vessel

// The paper's strategy: rescale the full tree's per-generation profile to the budget
// (generation_profile.hpp), then select generation by generation at random (seeded, with
// the portable UniformSource: the same seed gives the same mask everywhere) whole sibling
// groups among the daughters of kept vessels, so that the kept counts follow the target.
// Deficits pass to the next generations; what the last ones cannot hold is added deepest
// first, so that a binary tree keeps exactly the largest odd number <= budget (the whole
// tree if smaller). report gets the full, target and achieved profiles. InputError for a
// zero budget.
KeepMask prune_by_profile(const Network& full, std::size_t budget, std::uint64_t seed,
                          ProfileReport* report = nullptr);

// Keeps the root and the daughters of every kept vessel whose diameter is at least cutoff
// [m] (whole sibling groups; in a Murray tree, every vessel whose parent is that wide).
KeepMask prune_by_diameter(const Network& full, double cutoff);

// Keeps generations 0 .. max_generation. InputError when max_generation < 0.
KeepMask prune_by_generation(const Network& full, int max_generation);

// Keeps the subtree below the vessel with id subtree_id complete (with the path to it and
// its siblings along that path), and trims the rest by the profile strategy to the budget:
// the rest's profile (the full tree's less the subtree's) is rescaled to the budget less
// the subtree, the path counting against it. InputError when the subtree with its path
// exceeds the budget, the id does not exist, or the budget is zero. report's target is the
// rest's target plus the subtree's profile.
KeepMask prune_keeping_subtree(const Network& full, std::int64_t subtree_id, std::size_t budget,
                               std::uint64_t seed, ProfileReport* report = nullptr);

// The kept vessels as a network of their own, in their original order with their ids and
// fields (class included, as stored), the nodes they use in their original order with
// their ids and coordinates, blood, provenance and extra members kept from the full tree.
// Outlets and inlet are not copied: the pruned tree's outlets are new. std::invalid_argument
// when keep does not have one entry per vessel.
Network extract(const Network& full, const KeepMask& keep);

}  // namespace hemotree
