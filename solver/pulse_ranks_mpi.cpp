#include "solver/pulse_ranks_mpi.hpp"

#include "mpi/session.hpp"
#include "pulse/lumped_cut.hpp"

namespace hemotree {

MpiPulseRanks::MpiPulseRanks(const Network& net, std::vector<double> cost)
    : net_(net), cost_(std::move(cost)), partition_(partition_network(net, cost_, world_size())) {
  ranks_.ranks = world_size();
  ranks_.rank = world_rank();
  ranks_.top_rank = partition_.top_rank;
  ranks_.vessel_ranks = [this](const std::vector<bool>& zero_d) {
    std::vector<std::uint8_t> on_top(zero_d.size());
    for (std::size_t v = 0; v < zero_d.size(); ++v) on_top[v] = zero_d[v] ? 0 : 1;
    keep_on_top(net_, cost_, on_top, partition_);
    std::vector<std::int32_t> rank(partition_.rank_of_vessel.begin(), partition_.rank_of_vessel.end());
    for (const std::int32_t v : partition_.top) rank[static_cast<std::size_t>(v)] = partition_.top_rank;
    top_vessels_ = 0;
    for (const std::int32_t r : rank) top_vessels_ += r == partition_.top_rank ? 1 : 0;
    roots_ = lumped_cut(net_, subtree_lumped_order(net_, zero_d), rank, ranks_.ranks, partition_.top_rank, ranks_.rank).roots;
    return rank;
  };
  ranks_.link.up = [this](std::span<const double> numbers, std::exception_ptr failure, bool& failed) {
    if (!exchange_) exchange_ = std::make_unique<RootExchange>(MPI_COMM_WORLD, ranks_.top_rank, roots_);
    return exchange_->gather(numbers, failure, LumpedLink::up_per_root, failed);
  };
  ranks_.link.down = [this](std::span<const double> answers, std::exception_ptr failure) {
    return exchange_->scatter(answers, failure, LumpedLink::down_per_root, "the 0D step");
  };
}

}  // namespace hemotree
