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

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "distributed/network_cut.hpp"
#include "distributed/petsc_flow_network.hpp"
#include "distributed/steady_share.hpp"
#include "partition/partition.hpp"

#include "formats/network.hpp"
#include "physics/blood.hpp"
#include "steady/steady_flow.hpp"

namespace hemotree {

struct SteadyOverRanks {
  SteadyFlow flow;        // on rank 0; empty elsewhere
  std::string partition;  // the partition in one line (partition/partition.hpp's describe)
};

// The steady flow over the ranks set up once for several solves (the phase separation's
// passes, each with its own hematocrits): the rows, the partition, the cut and this rank's
// share, or PETSc's system, built by the constructor (collective; its refusals as below), and
// each solve as solve_steady_flow_over_ranks's.
class SteadyFlowOverRanks {
 public:
  SteadyFlowOverRanks(const Network& net, const Blood& blood, double inlet_flow);
  ~SteadyFlowOverRanks();
  SteadyFlowOverRanks(const SteadyFlowOverRanks&) = delete;
  SteadyFlowOverRanks& operator=(const SteadyFlowOverRanks&) = delete;
  // hematocrit: as solve_steady_flow_over_ranks's. Collective.
  SteadyOverRanks solve(std::span<const double> hematocrit = {});

 private:
  SteadyOverRanks solve_tree(std::span<const double> hematocrit);
  SteadyOverRanks solve_by_petsc(std::span<const double> hematocrit);
  const Network& net_;
  Blood blood_;
  SteadyRows rows_;
  Partition partition_;
  std::optional<TreeCut> cut_;
  std::optional<SteadyShare> share_;                    // a tree's
  std::vector<double> resistance_;                      // a tree's: per vessel, this rank's set
  std::vector<std::vector<std::int32_t>> held_lists_;   // a tree's, on rank 0: every rank's nodes
  std::unique_ptr<PetscFlowNetwork> petsc_;             // any other network's
  std::vector<double> inflow_;                          // its: the rows' inflows and the inlet's
};

// SettingError "ranks" where a network has more nodes than rank 0 can gather the results of.
void check_gathered_nodes(std::size_t nodes);

// The end of a tree's solve over ranks, whichever way the ranks hold the network: rows, per
// node this rank holds (the cut's held_nodes order), its pressure and the flow of its edge to
// its parent (0 at a root), gathered into rank 0's whole SteadyFlow of `vessels` vessels, the
// inlet's pressure at inlet_node (-1: NaN); held_lists, rank 0's every rank's nodes, made at
// the first call. The partition's line says how the network is held and what the exchange
// cost. Collective.
SteadyOverRanks gather_tree_flow(const TreeCut& cut, const Partition& partition, const char* holding,
                                 const MpiTreeSystem::Traffic& traffic, std::span<const double> rows,
                                 std::size_t vessels, std::int64_t inlet_node,
                                 std::vector<std::vector<std::int32_t>>& held_lists);

// InputError as solve_steady_flow's, or where the iterative solve does not converge;
// SettingError "ranks" where a tree's partition spreads its top over the ranks. hematocrit:
// per vessel its own discharge hematocrit, its resistance's (steady/steady_flow.hpp's
// vessel_resistances; empty: the blood's everywhere), alike on every rank.
SteadyOverRanks solve_steady_flow_over_ranks(const Network& net, const Blood& blood, double inlet_flow,
                                             std::span<const double> hematocrit = {});

}  // namespace hemotree
