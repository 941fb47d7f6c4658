#include "distributed/network_cut.hpp"

#include <cstdint>
#include <stdexcept>
#include <string>

#include "core/errors.hpp"
#include "core/setting_error.hpp"
#include "mpi/session.hpp"
#include "steady/steady_flow.hpp"

namespace hemotree {

void check_subtree_partition(const Partition& partition) {
  if (partition.method == Partition::Method::metis)
    throw SettingError("ranks", placeholder("ranks") + " " + std::to_string(partition.ranks) +
                                    ": a network with loops is split by METIS, and its distributed solve is not built "
                                    "yet: run it on one rank");
  if (partition.top_spread || partition.top_rank < 0)
    throw SettingError("ranks", placeholder("ranks") + " " + std::to_string(partition.ranks) +
                                    ": so many ranks spread the tree's top over them, which the distributed solve does "
                                    "not take yet: fewer (at most about the square root of an eighth of the vessels)");
}

TreeCut tree_cut(const Network& net, const Partition& partition) {
  check_subtree_partition(partition);
  std::vector<std::int32_t> owner(partition.rank_of_vessel.begin(), partition.rank_of_vessel.end());
  for (const std::int32_t v : partition.top) owner[static_cast<std::size_t>(v)] = TreeCut::top;
  try {
    return TreeCut(net.node_count(), net.from, net.to, owner, partition.ranks, partition.top_rank);
  } catch (const std::invalid_argument& e) {
    throw SettingError("ranks", placeholder("ranks") + ": the partition is not whole subtrees below a top: " + e.what());
  }
}

std::optional<TreeCut> steady_tree_cut(const Network& net, const Partition& partition) {
  if (partition.method == Partition::Method::metis) return std::nullopt;
  if (partition.top_spread || partition.top_rank < 0) return tree_cut(net, partition);  // refused, in words
  try {
    return tree_cut(net, partition);
  } catch (const SettingError&) {
    return std::nullopt;
  }
}

void check_one_partition(const Partition& partition) {
  std::uint64_t hash = 14695981039346656037ull;  // FNV-1a over the ranks of the vessels
  for (const std::int32_t r : partition.rank_of_vessel) hash = (hash ^ static_cast<std::uint32_t>(r)) * 1099511628211ull;
  std::uint64_t least = hash, greatest = hash;
  MPI_Allreduce(&hash, &least, 1, MPI_UINT64_T, MPI_MIN, MPI_COMM_WORLD);
  MPI_Allreduce(&hash, &greatest, 1, MPI_UINT64_T, MPI_MAX, MPI_COMM_WORLD);
  if (least != greatest)
    throw Collective<SettingError>("ranks", placeholder("ranks") + ": the ranks split the vessels differently (their "
                                                "builds or METIS differ): run every rank from one build");
}

void refuse_floating_part_everywhere(const Network& net, std::int64_t node) {
  try {
    refuse_floating_part(net, node);
  } catch (const InputError& e) {
    throw Collective<InputError>(e.what());
  }
}

}  // namespace hemotree
