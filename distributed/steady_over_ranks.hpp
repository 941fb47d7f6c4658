// The steady flow of a network of rigid vessels (steady/steady_flow.hpp's solve_steady_flow)
// over the ranks of the MPI session (mpi/session.hpp), the whole SteadyFlow gathered on rank 0.
// Every rank reads the whole network (for now). Collective.
//   - A tree fed by its inflow into outlets: the vessels partitioned by whole subtrees (one a
//     vessel: the solve costs each alike), each rank's resistances and boundary rows for its
//     share only, one distributed elimination (distributed/mpi_tree_system.hpp): the bits of
//     the one-process solve for any number of ranks.
//   - Any other network (loops, pressures prescribed at nodes): PETSc's conjugate gradients
//     with BoomerAMG over the ranks (distributed/petsc_flow_network.hpp), the nodes split as
//     the partition (METIS on loops) splits their vessels: the one-process solve's to about
//     1e-12 relative.
#pragma once

#include <span>
#include <string>

#include "formats/network.hpp"
#include "physics/blood.hpp"
#include "steady/steady_flow.hpp"

namespace hemotree {

struct SteadyOverRanks {
  SteadyFlow flow;        // on rank 0; empty elsewhere
  std::string partition;  // the partition in one line (partition/partition.hpp's describe)
};

// InputError as solve_steady_flow's, or where the iterative solve does not converge;
// SettingError "ranks" where a tree's partition spreads its top over the ranks. hematocrit:
// per vessel its own discharge hematocrit, its resistance's (steady/steady_flow.hpp's
// vessel_resistances; empty: the blood's everywhere), alike on every rank.
SteadyOverRanks solve_steady_flow_over_ranks(const Network& net, const Blood& blood, double inlet_flow,
                                             std::span<const double> hematocrit = {});

}  // namespace hemotree
