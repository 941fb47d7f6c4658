// The steady flow of a tree network of rigid vessels (steady/steady_flow.hpp's
// solve_steady_flow) over the ranks of the MPI session (mpi/session.hpp): the
// vessels partitioned by whole subtrees (one a vessel: the solve costs each alike), each
// rank's resistances and boundary rows for its share only, one distributed solve
// (distributed/mpi_tree_system.hpp), and the whole SteadyFlow gathered on rank 0: the bits
// of the one-process solve for any number of ranks. Every rank reads the whole network (for
// now). Collective.
#pragma once

#include <string>

#include "formats/network.hpp"
#include "physics/blood.hpp"
#include "steady/steady_flow.hpp"

namespace hemotree {

struct SteadyOverRanks {
  SteadyFlow flow;        // on rank 0; empty elsewhere
  std::string partition;  // the partition in one line (partition/partition.hpp's describe)
};

// InputError as solve_steady_flow's; SettingError "ranks" where the network is not a tree
// with its inflow and outlets (pressures prescribed at nodes; loops) or the partition's top
// spreads over the ranks.
SteadyOverRanks solve_steady_flow_over_ranks(const Network& net, const Blood& blood, double inlet_flow);

}  // namespace hemotree
