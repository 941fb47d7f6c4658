#include "solver/pulse_ranks_mpi.hpp"

#include "distributed/gather_rows.hpp"
#include "distributed/network_cut.hpp"
#include "formats/topology.hpp"
#include "mpi/session.hpp"
#include "solver/decisions_over_ranks.hpp"
#include "pulse/lumped_cut.hpp"

namespace hemotree {

// The partition by the given costs first: a network with loops or too many ranks is refused
// here, before the solver's steady solve; the top's weight needs the models, and the vessels
// are dealt again with it once the solver has chosen them (vessel_ranks).
MpiPulseRanks::MpiPulseRanks(const Network& net, std::vector<double> cost)
    : net_(net), cost_(std::move(cost)), partition_(partition_network(net, cost_, world_size())) {
  check_subtree_partition(partition_);
  check_one_partition(partition_);
  lead_with_the_top(partition_);  // rank 0 writes the top's state with the results (a checkpoint)
  ranks_.ranks = world_size();
  ranks_.rank = world_rank();
  ranks_.top_rank = partition_.top_rank;
  ranks_.vessel_ranks = [this](const std::vector<bool>& zero_d) {
    std::vector<std::uint8_t> on_top(zero_d.size());
    for (std::size_t v = 0; v < zero_d.size(); ++v) on_top[v] = zero_d[v] ? 0 : 1;
    // The top's rank takes its statistics on the step's path, a share in its wait for the
    // top's 1D substeps (docs/scaling.md, item 7): the top should hold x = N / ((P - 1)(1 + r)
    // + 1) of the N 0D vessels, r a sample's cost over a vessel's step. An extra weight W on
    // the tree's root (always the top's) deals it so: x + W = (N + W) / P.
    const int ranks = world_size();
    const auto n = static_cast<double>(std::count(zero_d.begin(), zero_d.end(), true));
    const double x = n / ((ranks - 1) * (1 + statistics_per_vessel_step) + 1);
    top_weight_ = ranks > 1 ? (n - ranks * x) / (ranks - 1) : 0;
    std::vector<double> cost = cost_;
    if (top_weight_ > 0) {
      cost[static_cast<std::size_t>(inlet_vessels(net_).front())] += top_weight_;  // a root: the top's
      partition_ = partition_network(net_, cost, ranks);
      check_subtree_partition(partition_);
      check_one_partition(partition_);
      lead_with_the_top(partition_);
    }
    keep_on_top(net_, cost, on_top, partition_);
    std::vector<std::int32_t> rank(partition_.rank_of_vessel.begin(), partition_.rank_of_vessel.end());
    for (const std::int32_t v : partition_.top) rank[static_cast<std::size_t>(v)] = partition_.top_rank;
    top_vessels_ = 0;
    for (const std::int32_t r : rank) top_vessels_ += r == partition_.top_rank ? 1 : 0;
    return rank;
  };
  ranks_.cut_made = [this](const LumpedCut& cut) { roots_ = cut.roots; };
  ranks_.link.up = [this](std::span<const double> numbers, std::exception_ptr failure, bool& failed) {
    if (!exchange_) exchange_ = std::make_unique<RootExchange>(MPI_COMM_WORLD, ranks_.top_rank, roots_);
    return exchange_->gather(numbers, failure, LumpedLink::up_per_root, failed);
  };
  ranks_.link.down = [this](std::span<const double> answers, std::exception_ptr failure, std::size_t per_root) {
    try {
      return exchange_->scatter(answers, failure, per_root, "the 0D step");
    } catch (const CollectiveFailure&) {
      breakdown_on_every_rank(failure);  // the solution's breakdown as the run reports it alone
      throw;
    }
  };
  ranks_.lead_whole = [](std::vector<double>& values, const std::vector<unsigned char>& mine) {
    // Every rank's own items to rank 0, the top's (lead_with_the_top above).
    std::vector<std::int32_t> place(values.size());
    for (std::size_t k = 0; k < values.size(); ++k) place[k] = mine[k] ? static_cast<std::int32_t>(k) : -1;
    gather_places(values, place, values.size(), values);
  };
  ranks_.make_whole = [](std::vector<double>& values, const std::vector<unsigned char>& mine) {
    // Every rank's (item, value) pairs to every rank.
    std::vector<double> pairs;
    for (std::size_t k = 0; k < values.size(); ++k)
      if (mine[k]) pairs.insert(pairs.end(), {static_cast<double>(k), values[k]});
    const int count = static_cast<int>(pairs.size());
    std::vector<int> counts(static_cast<std::size_t>(world_size())), offsets(counts.size(), 0);
    MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, MPI_COMM_WORLD);
    for (std::size_t r = 1; r < counts.size(); ++r) offsets[r] = offsets[r - 1] + counts[r - 1];
    std::vector<double> all(static_cast<std::size_t>(offsets.back() + counts.back()));
    MPI_Allgatherv(pairs.data(), count, MPI_DOUBLE, all.data(), counts.data(), offsets.data(), MPI_DOUBLE, MPI_COMM_WORLD);
    for (std::size_t j = 0; j < all.size(); j += 2) values[static_cast<std::size_t>(all[j])] = all[j + 1];
  };
}

}  // namespace hemotree
