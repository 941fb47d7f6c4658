// The linear periodic state (harmonic/linear_periodic.hpp) of a tree network over the ranks of
// the MPI session: the distended steady state over them (distributed/distended_over_ranks.hpp),
// then each rank's share of the vessels' lines, of each harmonic's nodal system and of the mean
// shift's one solve at w = 0, every solve the distributed elimination
// (distributed/mpi_harmonic_tree.hpp). The top's rank holds the vessels into the shares as
// ghosts (the steady state at their share ends sent to it once; their amplitudes there are its
// own solve's), so that every sum at a node of the top runs over the whole network's terms in
// the whole's order; the forced vessels (the run's 1D ones, whose mean shift reads both ends'
// junctions) are kept on the top. Each rank ends with its share of the one-process solution,
// bit for bit, for any number of ranks. Collective.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "distributed/root_exchange.hpp"
#include "distributed/tree_share.hpp"
#include "formats/network.hpp"
#include "partition/partition.hpp"
#include "harmonic/linear_periodic.hpp"
#include "physics/blood.hpp"
#include "physics/tube_law.hpp"
#include "physics/viscosity_table.hpp"

namespace hemotree {

struct LinearPeriodicOverRanks {
  LinearPeriodic periodic;                   // what this rank holds of it (periodic.holds)
  std::vector<std::int32_t> vessels, nodes;  // this rank's: increasing vessels, its nodes (TreeCut::held_nodes)
  Partition partition;                       // the vessels' split (the same on every rank)
  std::optional<TreeCut> cut;                // and the tree's, by it (none on a graph's solve)
  RootExchange::Traffic traffic;             // this rank's exchanges in the harmonics' solves
  // Where the results are: each vessel's rank (every rank alike), and on rank 0 per rank its
  // vessels (increasing) and its nodes (in that rank's `nodes`' order).
  std::vector<std::vector<std::int32_t>> vessels_of, nodes_of;
  std::vector<std::int32_t> vessel_rank;
  std::string solver;  // how the harmonics were solved over the ranks, in words
};

// The arguments of the one-process solve_linear_periodic (the steady state is solved here, at
// the inlet's mean flow). A tree fed by its inflow: the vessels are split by whole subtrees,
// one a vessel; where a forced vessel (shift_source: a 1D vessel of the run) crosses the cut,
// every forced vessel and those above it move to the top's rank (partition/'s keep_on_top),
// their steady state with them; a spread top is refused (SettingError "ranks"). A network
// with loops or a pressure held at a node: split by METIS, each harmonic's system over the
// ranks by PETSc (petsc_harmonic_network.hpp), the plain solve's to its 1e-10 (every rank holds
// every vessel's line; the solves and the results are divided). InputError as the one-process
// solve, on every rank alike.
LinearPeriodicOverRanks solve_linear_periodic_over_ranks(const Network& net, const Blood& blood,
                                                         std::span<const TubeLaw> laws, const ViscosityTable& viscosity,
                                                         int harmonics, int threads,
                                                         const std::function<bool(const VesselLine&)>& shift_source);

// The periodic state at one instant t over the ranks (harmonic/linear_periodic.hpp's
// solve_periodic_instant, a pulsatile run's start): the same split and set-up, `keep` (the
// run's 1D vessels, known to every rank) kept on the top. Each rank's nodes' pressures and
// vessels' middle flows in `instant` (whole-network arrays, its entries set), `along` what it
// holds of the kept vessels: the one-process instant's bits. Collective.
struct PeriodicInstantOverRanks {
  PeriodicInstant instant;
  std::vector<std::int32_t> vessels, nodes;  // this rank's
  Partition partition;
  TreeCut cut;
};
PeriodicInstantOverRanks solve_periodic_instant_over_ranks(const Network& net, const Blood& blood,
                                                           std::span<const TubeLaw> laws, const ViscosityTable& viscosity,
                                                           int harmonics, double time, const std::vector<bool>& keep,
                                                           int threads, bool shift_mean);

}  // namespace hemotree
