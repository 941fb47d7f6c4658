// A tree network's nodal system cut by its partition (partition/): the network's nodes, each
// vessel an edge (from, to), as the steady flow's and the 0D vessels' systems take them, and
// each vessel on the rank the partition gave it, the top's on the top's rank
// (distributed/tree_share.hpp).
#pragma once

#include "distributed/tree_share.hpp"
#include "formats/network.hpp"
#include "partition/partition.hpp"

#include <cstdint>
#include <optional>

namespace hemotree {

// Every rank calls it with the same network and partition (partition_network is
// deterministic), so every rank holds the same cut and refuses alike.
// SettingError "ranks" where the partition cannot be swept so yet: a network with loops
// (METIS's pieces need the distributed sparse solver) or a top spread over the ranks (more
// ranks than about the square root of an eighth of the vessels).
TreeCut tree_cut(const Network& net, const Partition& partition);
// The cut a steady solve over ranks takes where it can (distributed/steady_over_ranks.hpp):
// none where the partition is METIS's (a network with loops) or where the tree's node labels
// hang it from another node than its inlet, so that the nodal system's elimination is not cut
// into the partition's flow subtrees (vgen's and vprune's labels start at the inlet): PETSc
// solves those. A top spread over the ranks is refused in tree_cut's words.
std::optional<TreeCut> steady_tree_cut(const Network& net, const Partition& partition);
// The same refusals alone, of a partition a solve over ranks takes by subtrees.
void check_subtree_partition(const Partition& partition);

// Every rank computed the partition itself: the same one where every rank runs the same
// build. Checked (a hash of it, its least and greatest over the ranks: collective), since
// ranks that split the vessels differently would each solve a different system; refused on
// every rank alike (SettingError "ranks").
void check_one_partition(const Partition& partition);

// steady/'s refusal of a tree whose part at `node` has no path to ground, thrown on every rank
// alike (the distributed solve said it on every rank: mpi/session.hpp's Collective).
[[noreturn]] void refuse_floating_part_everywhere(const Network& net, std::int64_t node);

}  // namespace hemotree
