// The vessels of a network split over P ranks for a distributed run (issue 24), each vessel
// weighted by its cost. A forest of trees (every node entered by at most one vessel, no loop)
// is split into whole subtrees: subtrees with daughters are split from the top, largest first,
// until the largest is an eighth of a rank's share, and the pieces dealt largest first, each
// to the least loaded rank (Graham's LPT rule: the largest load at most the mean plus the
// largest piece). The vessels split off above them, the top, are dealt as one more piece, so
// that the top's small system is one rank's; where the top outgrows a rank's share (many
// ranks for the vessels: P above about the square root of an eighth of them), each top
// vessel goes with its first daughter instead. Of the cuts on the way the best dealt is kept.
// Any other graph is split by METIS (multilevel k-way on the nodes, each weighted by the cost
// of the vessels leaving it), a vessel going with its `from` node.
// Deterministic: the same partition for the same network, costs and P.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "formats/network.hpp"

namespace hemotree {

struct Partition {
  enum class Method { single, subtrees, metis };
  Method method = Method::single;
  int ranks = 1;
  std::vector<std::int32_t> rank_of_vessel;  // one per vessel, in [0, ranks)
  std::vector<double> cost;                  // per rank: the sum of its vessels' costs
  std::vector<std::size_t> vessels;          // per rank
  std::size_t cut_nodes = 0;                 // nodes whose vessels lie on more than one rank
  std::vector<std::int32_t> top;             // subtrees: the vessels above the cut
  int top_rank = 0;                          // subtrees: the rank that holds them (-1: spread)
  bool top_spread = false;                   // subtrees: each top vessel with its first daughter

  // The largest rank's cost over the mean (1: perfect balance).
  double imbalance() const;
};

const char* to_string(Partition::Method method);  // "one rank", "subtrees", "METIS"

// P in [1, vessel count]: SettingError "ranks" for P < 1, for more ranks than vessels, and
// for a partition that would leave a rank without a vessel. cost: one positive number per
// vessel.
Partition partition_network(const Network& net, std::span<const double> cost, int ranks);

// A tree's partition by subtrees with the vessels marked in on_top (a byte per vessel) moved
// to the top's rank, with every vessel above them: a distributed run's vessels that no cut
// may cross (the linear periodic state's 1D vessels). Every other vessel keeps its rank, so
// the subtrees below a moved vessel become pieces of their own on the rank they were on, and
// only the moved vessels change hands. Nothing to do on one rank (and METIS's partitions and
// a spread top have no top to keep). SettingError "ranks" where a rank is left without a vessel.
void keep_on_top(const Network& net, std::span<const double> cost, std::span<const std::uint8_t> on_top, Partition& p);

// The top's rank made rank 0, the rank that gathers a run's results (ranks 0 and the top's
// swap their vessels): what a run over ranks that writes the top's state with the results
// (its checkpoint) takes. The same balance and cut. Nothing to do without a top on one rank.
void lead_with_the_top(Partition& p);

// Each node's rank, where a distributed solve (PETSc) assembles its rows: the rank of a vessel
// leaving it (METIS's pieces go with their `from` nodes), else of one entering it; rank 0
// for a node no vessel touches.
std::vector<std::int32_t> node_owners(const Network& net, const Partition& partition);

// Nodes whose vessels lie on more than one rank.
std::size_t count_cut_nodes(const Network& net, std::span<const std::int32_t> rank_of_vessel);

// One line: "4 ranks by subtrees: 1325 to 1326 vessels a rank, cost imbalance 1.001 (the
// largest over the mean), 9 cut nodes, the top's 5 vessels on rank 3".
std::string describe(const Partition& partition);

}  // namespace hemotree
