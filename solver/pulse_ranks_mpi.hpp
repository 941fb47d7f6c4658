// A pulsatile run over MPI ranks as the solver takes it (pulse/pulse_solver.hpp's PulseRanks),
// dealt once the solver has chosen the models, one of two ways:
//  - a tree: partitioned by subtrees, the 1D vessels and every vessel above them moved to the
//    top's rank (partition/keep_on_top), and each step's messages over MPI, their exchange
//    made at the first step from the cut's roots per rank;
//  - where that leaves a rank without a vessel (the large arteries' models, nearly all 1D),
//    or the network has loops (no top): the 1D vessels spread, the
//    partition by each vessel's step (subtrees, or METIS), the 0D vessels meeting at a node
//    on one rank; the traces at junctions across the cut exchanged with each neighbouring
//    rank (MPI_Isend, MPI_Irecv) at every evaluation, the couplings of 1D ends to another
//    rank's 0D nodes at every step, failures by one MPI_Allreduce a step; the 0D vessels spread
//    too where keeping each system of them on one rank would leave a rank empty (or, where no
//    1D vessel meets them, the step out of balance), each step solved by PETSc
//    (distributed/petsc_nodal_system.hpp).
// Per-item numbers are made whole on every rank (MPI_Allgatherv of each rank's items and
// values: the compliance balance's, once a cycle).
#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <span>
#include <vector>

#include "distributed/neighbour_exchange.hpp"
#include "distributed/root_exchange.hpp"
#include "formats/network.hpp"
#include "partition/partition.hpp"
#include "pulse/pulse_solver.hpp"

namespace hemotree {

class PetscNodalSystem;

// Where a tree can be dealt either way: its top holding every 1D vessel wherever that leaves
// every rank a vessel (what red cells and tracers over ranks take: their transport follows
// the subtrees under the top), the 1D vessels spread wherever that balances the step, or
// spread wherever that leaves every rank a vessel.
enum class OneDLayout { top_where_possible, balanced, spread };

class MpiPulseRanks {
 public:
  // Over MPI_COMM_WORLD's ranks; cost: per vessel, its weight in a tree's partition by
  // subtrees. The network must outlive this. SettingError "ranks" (every rank alike) for more
  // ranks than vessels here, and, as the solver deals the vessels, for a tree's top spread over
  // the ranks (distributed/network_cut.hpp's check_subtree_partition) or a rank left without a
  // vessel.
  MpiPulseRanks(const Network& net, std::vector<double> cost, OneDLayout layout = OneDLayout::top_where_possible);
  MpiPulseRanks(const MpiPulseRanks&) = delete;  // the link refers to this
  MpiPulseRanks& operator=(const MpiPulseRanks&) = delete;

  const PulseRanks& ranks() const { return ranks_; }
  // Once every solver of the run is built (the run's and its settling one, which takes the
  // same deal): what only dealing needed, every vessel's cost and rank (each solver holds its
  // own vessels' ranks where it needs them), freed on every rank. A deal after it is a logic
  // error.
  void end_dealing();
  // After the solver is built: the partition (with the 1D vessels kept on the top, or spread;
  // its per-vessel ranks gone after end_dealing), and the vessels the top's rank holds (0
  // where spread).
  const Partition& partition() const { return partition_; }
  bool one_d_spread() const { return one_d_spread_; }
  // Whether the 0D vessels are spread over the ranks (a 0D system with loops), and the
  // solves of its steps on this rank (the run's solver's and a settling solver's): how many,
  // their iterations and preconditioner set-ups, the seconds inside them, PETSc's method.
  bool zero_d_spread() const { return zero_d_spread_; }
  struct ZeroDSolves {
    std::size_t solves = 0, iterations = 0, setups = 0;
    double seconds = 0;
    std::string method;
  };
  ZeroDSolves zero_d_solves() const;
  // With the 1D vessels spread, this rank's messages (sent to its neighbours: traces, coupled
  // ends), their bytes, its reductions (failures), and the seconds inside them, waiting
  // included.
  struct SpreadTraffic : NeighbourTraffic {
    std::size_t reductions = 0;
  };
  const SpreadTraffic& spread_traffic() const { return spread_traffic_; }
  std::size_t top_vessels() const { return top_vessels_; }
  const RootExchange* exchange() const { return exchange_.get(); }  // null before the first step
  // Per rank, its root vessels (LumpedCut::roots): the messages' sizes. Known once the solver is built.
  const std::vector<int>& roots() const { return roots_; }
  // What the top's rank was weighed by besides its vessels, in 0D vessels: its statistics.
  double top_weight() const { return top_weight_; }
  // A statistics sample's cost over a 0D vessel's step, taken every step (up to 500 steps a
  // cycle): measured on the 421,047-vessel tree over 2 ranks, the best of the top's extra
  // weights 0, 0.1, 0.2, 0.3 of the vessels (bench/README.md) is 0.2, which this gives.
  static constexpr double statistics_per_vessel_step = 0.5;
  // The largest rank's step cost over the mean that a tree's spread partition may have to be
  // taken instead of its top (OneDLayout::balanced; docs/scaling.md, item 11).
  static constexpr double spread_balance = 1.05;

 private:
  const Network& net_;
  std::vector<double> cost_;
  OneDLayout layout_;
  Partition partition_;
  PulseRanks ranks_;
  std::vector<int> roots_;
  std::size_t top_vessels_ = 0;
  double top_weight_ = 0;
  std::unique_ptr<RootExchange> exchange_;
  std::optional<VesselRanks> dealt_;
  std::vector<bool> dealt_zero_d_;
  bool one_d_spread_ = false, dealing_ended_ = false;
  SpreadTraffic spread_traffic_;
  bool zero_d_spread_ = false;
  std::vector<std::shared_ptr<PetscNodalSystem>> halo_systems_;
  VesselRanks deal(const std::vector<bool>& zero_d, std::span<const double> step_cost);
  VesselRanks on_top(const std::vector<bool>& zero_d);
  // The 1D vessels spread, where the partition leaves no rank empty and its imbalance is at
  // most most_imbalance (infinite: it must; SettingError "ranks" where a rank is left empty).
  std::optional<VesselRanks> spread(const std::vector<bool>& zero_d, std::span<const double> step_cost,
                                    double most_imbalance);
};

}  // namespace hemotree
