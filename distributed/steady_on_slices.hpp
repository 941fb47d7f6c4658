// The steady flow of a tree over the ranks of the MPI session with each rank holding only its
// slice of the network (formats/network_slice.hpp), not the whole: every rank reads the
// topology (ids and ends: what the partition and the cut need), partitions and cuts it as
// solve_steady_flow_over_ranks does, reads its own vessels' rows (its nodes' edges to their
// parents) and the nodes they touch, forms its nodes' rows and its vessels' resistances from
// them, and takes part in the one distributed elimination; rank 0 gathers the pressures and
// flows. The same arithmetic in the same order as solve_steady_flow_over_ranks: the plain
// run's bits for any number of ranks.
//
// Rank 0 holds the whole network besides: it checks it as the plain command does and writes
// the results from it (each rank writing its own rows is the next step, docs/scaling.md).
// A rank's memory is its slice and what is still whole: the topology, the partition and the
// cut, about 80 bytes a vessel of the network (bench/README.md, "Each rank its slice").
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "distributed/steady_over_ranks.hpp"
#include "distributed/tree_share.hpp"
#include "formats/network.hpp"
#include "formats/network_slice.hpp"
#include "partition/partition.hpp"
#include "physics/blood.hpp"

namespace hemotree {

// Set up once (the topology's partition and cut, this rank's slice and share) for one solve or
// several (the phase separation's passes). Collective.
class SteadyFlowOnSlices {
 public:
  // held: on rank 0 the whole network, on the others its topology (formats/network_slice.hpp's
  // read_network_topology of path, the HDF5 file they read their slices from). blood_of: the
  // run's blood of a network (its file's, with the run's rheology). Errors as
  // solve_steady_flow_over_ranks's.
  SteadyFlowOnSlices(const Network& held, const std::string& path, const std::function<Blood(const Network&)>& blood_of);
  ~SteadyFlowOnSlices();
  SteadyFlowOnSlices(const SteadyFlowOnSlices&) = delete;
  SteadyFlowOnSlices& operator=(const SteadyFlowOnSlices&) = delete;

  // False, on every rank alike, where the network is not a tree in the tree form (an inlet,
  // outlets: boundaries at nodes or loops take PETSc's solve of the whole network, which every
  // rank then reads), or where its labels do not follow its subtrees: the caller then solves
  // it whole.
  bool serves() const { return cut_.has_value(); }
  // This rank's slice: its vessels' rows in the whole network, increasing.
  std::span<const std::int32_t> vessels() const { return slice_.vessel_row; }
  // hematocrit: per vessel of vessels(), its discharge hematocrit (empty: the blood's). The
  // whole SteadyFlow on rank 0. Collective.
  SteadyOverRanks solve(std::span<const double> hematocrit = {});

 private:
  struct Share;
  Partition partition_;
  std::optional<TreeCut> cut_;
  NetworkSlice slice_;
  std::unique_ptr<Share> share_;
  std::size_t vessel_count_ = 0;  // the whole network's
  std::int64_t lead_inlet_node_ = -1;         // rank 0's: the inlet's node, given or found by the checks
  Blood blood_;
};

}  // namespace hemotree
