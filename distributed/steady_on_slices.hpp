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
// A rank's memory is its slice and the whole topology: about 40 bytes a vessel (ids, ends,
// partition, cut) against the whole network's 200 and more.
#pragma once

#include <functional>
#include <optional>
#include <string>

#include "distributed/steady_over_ranks.hpp"
#include "formats/network.hpp"
#include "physics/blood.hpp"

namespace hemotree {

// held: on rank 0 the whole network, on the others its topology (formats/network_slice.hpp's
// read_network_topology of path, the HDF5 file they read their slices from). blood_of: the run's blood of a network (its file's, with the run's rheology).
// None, on every rank alike, where the network is not a tree in the tree form (an inlet,
// outlets: boundaries at nodes or loops take PETSc's solve of the whole network, which every
// rank then reads), or where its partition cannot be cut into subtrees; the caller then
// solves it whole. Errors as solve_steady_flow_over_ranks's. Collective.
std::optional<SteadyOverRanks> solve_steady_flow_on_slices(const Network& held, const std::string& path,
                                                           const std::function<Blood(const Network&)>& blood_of);

}  // namespace hemotree
