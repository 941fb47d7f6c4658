// The two ways partition_network splits a network (partition/partition.hpp), each on its own:
// whole subtrees of a forest, and METIS on any graph. Both fill rank_of_vessel; the caller
// counts the costs, the vessels and the cut nodes.
#pragma once

#include <span>

#include "partition/partition.hpp"

namespace hemotree {

// Every node entered by at most one vessel and every vessel reached from a vessel whose
// `from` node none enters: a forest of rooted trees.
bool is_forest(const Network& net);

Partition partition_subtrees(const Network& net, std::span<const double> cost, int ranks);
Partition partition_with_metis(const Network& net, std::span<const double> cost, int ranks);

}  // namespace hemotree
