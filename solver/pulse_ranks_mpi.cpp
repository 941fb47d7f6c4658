#include "solver/pulse_ranks_mpi.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include "core/setting_error.hpp"
#include "distributed/gather_rows.hpp"
#include "distributed/neighbour_exchange.hpp"
#include "distributed/network_cut.hpp"
#include "distributed/petsc_nodal_system.hpp"
#include "formats/topology.hpp"
#include "mpi/session.hpp"
#include "solver/decisions_over_ranks.hpp"
#include "pulse/lumped_cut.hpp"
#include "pulse/lumped_halo.hpp"
#include "pulse/lumped_order.hpp"

namespace hemotree {

// The partition by the given costs first: too many ranks are refused here, before the
// solver's steady solve; which way the vessels are dealt, and the top's weight, need the
// models, and the vessels are dealt again once the solver has chosen them (vessel_ranks).
MpiPulseRanks::MpiPulseRanks(const Network& net, std::vector<double> cost, OneDLayout layout)
    : net_(net), cost_(std::move(cost)), layout_(layout), partition_(partition_network(net, cost_, world_size())) {
  check_one_partition(partition_);
  if (partition_.method == Partition::Method::subtrees && !partition_.top_spread) lead_with_the_top(partition_);
  ranks_.ranks = world_size();
  ranks_.rank = world_rank();
  ranks_.top_rank = partition_.top_rank;
  ranks_.vessel_ranks = [this](const std::vector<bool>& zero_d, std::span<const double> step_cost) {
    // The run's partition, made once: a settling solver of the same models takes the same.
    if (dealing_ended_) throw std::logic_error("MpiPulseRanks: a deal after end_dealing");
    if (!dealt_ || dealt_zero_d_ != zero_d) {
      dealt_ = deal(zero_d, step_cost);
      dealt_zero_d_ = zero_d;
      one_d_spread_ = dealt_->one_d_spread;
    }
    return *dealt_;
  };
  ranks_.exchange = [this](std::span<const int> neighbours, const std::vector<std::vector<double>>& send,
                           std::vector<std::vector<double>>& receive) {
    exchange_with_neighbours(neighbours, send, receive, 21, spread_traffic_);
  };
  ranks_.least_key = [this](std::int64_t key) {
    const double started = MPI_Wtime();
    std::int64_t least = key;
    MPI_Allreduce(&key, &least, 1, MPI_INT64_T, MPI_MIN, MPI_COMM_WORLD);
    ++spread_traffic_.reductions;
    spread_traffic_.seconds += MPI_Wtime() - started;
    return least;
  };
  ranks_.cut_made = [this](const LumpedCut& cut) { roots_ = cut.roots; };
  ranks_.halo_link = [this](const LumpedHaloSystem& halo) {
    // PETSc's solve over every rank's rows (distributed/petsc_nodal_system.hpp), kept here for
    // the run's account of its time.
    auto system = std::make_shared<PetscNodalSystem>(halo.key_rank, halo.node_key, halo.a, halo.b);
    halo_systems_.push_back(system);
    LumpedHaloLink link;
    link.least = ranks_.least_key;
    link.solve = [system](std::span<const double> conductance, std::span<const double> shunt, std::span<const double> rhs,
                          std::span<double> x) { system->solve(conductance, shunt, rhs, x); };
    link.solve_again = [system](std::span<const double> rhs, std::span<double> x) { system->solve_again(rhs, x); };
    link.fill_ghosts = [system](std::span<double> values) { system->fill_ghosts(values); };
    link.sum = [this](std::span<double> values) {  // each value one rank's, the others' zero: exact
      const double started = MPI_Wtime();
      MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
      ++spread_traffic_.reductions;
      spread_traffic_.seconds += MPI_Wtime() - started;
    };
    return link;
  };
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
  ranks_.lead_places = [](std::span<const double> values, std::span<const std::int32_t> place, std::size_t count) {
    return gather_places(values, place, count);
  };
  ranks_.from_lead = [](std::vector<double>& values) { take_lead_values(values); };  // rank 0's, as lead_whole's
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

void MpiPulseRanks::end_dealing() {
  dealing_ended_ = true;
  std::vector<double>().swap(cost_);
  std::vector<std::int32_t>().swap(partition_.rank_of_vessel);  // describe() reads the counts alone
  dealt_.reset();
  std::vector<bool>().swap(dealt_zero_d_);
}

VesselRanks MpiPulseRanks::deal(const std::vector<bool>& zero_d, std::span<const double> step_cost) {
  // A network with loops (no top): the 1D vessels spread (docs/scaling.md, "1D vessels across a
  // cut"). A tree: spread where that balances its step (OneDLayout::balanced), else its top
  // holds every 1D vessel, as long as that leaves every rank a vessel (a tree nearly all 1D,
  // the large arteries' models, spread).
  const int ranks = world_size();
  constexpr double must = std::numeric_limits<double>::infinity();
  if (ranks > 1 && (partition_.method == Partition::Method::metis || layout_ == OneDLayout::spread))
    return *spread(zero_d, step_cost, must);
  if (ranks > 1 && layout_ == OneDLayout::balanced)
    if (std::optional<VesselRanks> spread_out = spread(zero_d, step_cost, spread_balance)) return *spread_out;
  try {
    return on_top(zero_d);
  } catch (const SettingError&) {
    // No top that leaves every rank a vessel, or a top spread over many ranks: spread needs
    // neither (its own refusal, where it has one, is said instead).
    if (ranks == 1) throw;
    return *spread(zero_d, step_cost, must);
  }
}

VesselRanks MpiPulseRanks::on_top(const std::vector<bool>& zero_d) {
  const int ranks = world_size();
  check_subtree_partition(partition_);
  std::vector<std::uint8_t> on_top(zero_d.size());
  for (std::size_t v = 0; v < zero_d.size(); ++v) on_top[v] = zero_d[v] ? 0 : 1;
  // The top's rank takes its statistics on the step's path, a share in its wait for the
  // top's 1D substeps (docs/scaling.md, item 7): the top should hold x = N / ((P - 1)(1 + r)
  // + 1) of the N 0D vessels, r a sample's cost over a vessel's step. An extra weight W on
  // the tree's root (always the top's) deals it so: x + W = (N + W) / P.
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
  return VesselRanks{rank, false};
}

std::optional<VesselRanks> MpiPulseRanks::spread(const std::vector<bool>& zero_d, std::span<const double> step_cost,
                                                  double most_imbalance) {
  // The partition by each vessel's step, then the 0D vessels meeting at nodes kept on one rank
  // (a 0D system is one rank's; the 1D ends at its nodes may be elsewhere): each such group to
  // the rank that holds most of its cost.
  const std::size_t n = zero_d.size();
  Partition p = partition_network(net_, step_cost, world_size());
  check_one_partition(p);  // every rank's the same (collective: before any return)
  std::vector<std::int32_t> parent(n);
  for (std::size_t v = 0; v < n; ++v) parent[v] = static_cast<std::int32_t>(v);
  auto find = [&](std::int32_t v) {
    while (parent[static_cast<std::size_t>(v)] != v) v = parent[static_cast<std::size_t>(v)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(v)])];
    return v;
  };
  std::vector<std::int32_t> at_node(net_.node_count(), -1);  // a 0D vessel there, the first
  for (std::size_t v = 0; v < n; ++v)
    if (zero_d[v])
      for (const std::int32_t node : {net_.from[v], net_.to[v]}) {
        std::int32_t& u = at_node[static_cast<std::size_t>(node)];
        if (u < 0) {
          u = static_cast<std::int32_t>(v);
          continue;
        }
        const std::int32_t a = find(static_cast<std::int32_t>(v)), b = find(u);
        if (a != b) parent[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
      }
  const auto ranks = static_cast<std::size_t>(p.ranks);
  std::vector<std::int32_t> root(n);
  for (std::size_t v = 0; v < n; ++v) root[v] = find(static_cast<std::int32_t>(v));
  // The 0D vessels may be spread over the ranks as the partition has them, each rank with a
  // halo (pulse/lumped_halo.hpp), where keeping each system of them whole would leave a rank
  // empty, or, where no 1D vessel meets them (a network of capillaries), the step out of
  // balance: the step is then solved over every rank's rows (PETSc), to about 1e-9 of the
  // one-process solve, not bit for bit; a network whose 1D and 0D vessels balance as they are
  // keeps its bits.
  bool one_d_meets_zero_d = false, any_zero_d = false;
  for (std::size_t v = 0; v < n; ++v) {
    any_zero_d = any_zero_d || zero_d[v];
    if (!zero_d[v])
      for (const std::int32_t node : {net_.from[v], net_.to[v]}) one_d_meets_zero_d = one_d_meets_zero_d || at_node[static_cast<std::size_t>(node)] >= 0;
  }
  const Partition as_given = p;
  // Per group of 0D vessels (its root vessel) and rank, the cost there.
  std::map<std::int32_t, std::vector<double>> cost_on;
  for (std::size_t v = 0; v < n; ++v) {
    if (!zero_d[v]) continue;
    auto& c = cost_on[root[v]];
    c.resize(ranks, 0.0);
    c[static_cast<std::size_t>(p.rank_of_vessel[v])] += step_cost[v];
  }
  std::map<std::int32_t, std::int32_t> group_rank;
  for (const auto& [g, c] : cost_on)
    group_rank[g] = static_cast<std::int32_t>(std::max_element(c.begin(), c.end()) - c.begin());
  for (std::size_t v = 0; v < n; ++v)
    if (const auto it = group_rank.find(root[v]); it != group_rank.end()) p.rank_of_vessel[v] = it->second;
  auto tally = [&](Partition& q) {
    q.cost.assign(ranks, 0.0);
    q.vessels.assign(ranks, 0);
    for (std::size_t v = 0; v < n; ++v) {
      q.cost[static_cast<std::size_t>(q.rank_of_vessel[v])] += step_cost[v];
      ++q.vessels[static_cast<std::size_t>(q.rank_of_vessel[v])];
    }
  };
  tally(p);
  const bool leaves_empty = std::find(p.vessels.begin(), p.vessels.end(), std::size_t{0}) != p.vessels.end();
  const bool unbalanced = leaves_empty || (p.imbalance() > spread_balance && !one_d_meets_zero_d);
  bool zero_d_spread = false;
  if (unbalanced && !std::isfinite(most_imbalance) && as_given.method == Partition::Method::metis && any_zero_d) {
    p = as_given;
    zero_d_spread = true;
    // Every 0D vessel on a rank that owns one of its nodes (what the halo's transport needs).
    if (hold_at_an_own_node(net_, subtree_lumped_order(net_, zero_d), p.rank_of_vessel, p.ranks) > 0) tally(p);
  }
  if (const auto empty = std::find(p.vessels.begin(), p.vessels.end(), std::size_t{0}); empty != p.vessels.end()) {
    if (std::isfinite(most_imbalance)) return std::nullopt;
    std::map<std::int32_t, std::size_t> joined;
    for (std::size_t v = 0; v < n; ++v)
      if (group_rank.count(root[v])) ++joined[root[v]];
    std::size_t largest = 0;
    for (const auto& [g, count] : joined) largest = std::max(largest, count);
    throw SettingError("ranks", placeholder("ranks") + " " + std::to_string(p.ranks) + ": rank " +
                                    std::to_string(empty - p.vessels.begin()) + " would step no vessel: one rank steps " +
                                    "the 0D vessels joined at their nodes (a tree's are spread by subtrees only under a " +
                                    "top), and here they join " + std::to_string(largest) + " of the " + std::to_string(n) +
                                    " vessels: run it on fewer ranks");
  }
  if (p.imbalance() > most_imbalance) return std::nullopt;
  p.cut_nodes = count_cut_nodes(net_, p.rank_of_vessel);
  p.top.clear();  // no top: every rank steps its own 1D vessels
  p.top_spread = false;
  partition_ = std::move(p);
  top_vessels_ = 0;
  top_weight_ = 0;
  zero_d_spread_ = zero_d_spread;
  return VesselRanks{std::vector<std::int32_t>(partition_.rank_of_vessel.begin(), partition_.rank_of_vessel.end()), true,
                     zero_d_spread};
}

MpiPulseRanks::ZeroDSolves MpiPulseRanks::zero_d_solves() const {
  ZeroDSolves all;
  for (const auto& system : halo_systems_) {
    all.solves += system->solves();
    all.iterations += system->iterations();
    all.setups += system->preconditioner_setups();
    all.seconds += system->seconds();
  }
  if (!halo_systems_.empty()) all.method = halo_systems_.front()->method();
  return all;
}

}  // namespace hemotree
