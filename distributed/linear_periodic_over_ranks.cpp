#include "distributed/linear_periodic_over_ranks.hpp"

#include <algorithm>
#include <exception>
#include <memory>
#include <optional>
#include <utility>

#include <mpi.h>

#include "core/errors.hpp"
#include "core/setting_error.hpp"
#include "core/units.hpp"
#include "distributed/distended_over_ranks.hpp"
#include "distributed/harmonic_tree_share.hpp"
#include "distributed/mpi_harmonic_tree.hpp"
#include "distributed/network_cut.hpp"
#include "distributed/petsc_harmonic_network.hpp"
#include "formats/run_boundaries.hpp"
#include "mpi/session.hpp"
#include "partition/partition_methods.hpp"

namespace hemotree {

namespace {

// The top's rank receives, per share root r, the steady pressure at r and the flow of its
// vessel into the top (the ghosts' steady state), into its whole-network arrays.
void send_ghosts_to_top(const TreeCut& cut, SteadyFlow& steady) {
  const int rank = world_rank();
  RootExchange exchange(MPI_COMM_WORLD, cut);
  std::vector<double> message;
  for (const std::int32_t r : cut.roots[static_cast<std::size_t>(rank)]) {
    const auto node = static_cast<std::size_t>(r);
    message.push_back(steady.node_pressure[node]);
    message.push_back(steady.flow[static_cast<std::size_t>(cut.parent_edge[node])]);
  }
  exchange.round(message, nullptr, 2, 0,
                 [&](std::span<const double> all, std::span<double>) {
                   std::size_t slot = 0;
                   for (const auto& roots : cut.roots)
                     for (const std::int32_t r : roots) {
                       const auto node = static_cast<std::size_t>(r);
                       steady.node_pressure[node] = all[2 * slot];
                       steady.flow[static_cast<std::size_t>(cut.parent_edge[node])] = all[2 * slot + 1];
                       ++slot;
                     }
                   return RootExchange::solved;
                 },
                 "the ghosts' steady state");
}

// The vessels split over the ranks by whole subtrees (one a vessel) and the tree cut by it;
// refusals in words on every rank alike.
std::pair<Partition, TreeCut> split(const Network& net) {
  Partition partition;
  std::optional<TreeCut> cut;
  on_every_rank([&] {
    partition = partition_network(net, std::vector<double>(net.vessel_count(), 1.0), world_size());
    cut.emplace(tree_cut(net, partition));  // loops, a spread top: refused in words
  });
  check_one_partition(partition);
  return {std::move(partition), std::move(*cut)};
}

// The forced vessels moved to the top's rank (keep_on_top) and the tree cut again; their
// steady state (flow, end pressures) sent there from the ranks that held them, and every
// rank's vessels and nodes those of the new cut: the distended state of the new cut, without
// solving it again.
void keep_forced_on_top(const Network& net, std::span<const std::uint8_t> forced, Partition& partition, TreeCut& cut,
                        DistendedOverRanks& distended) {
  const std::vector<std::int32_t> old_rank = cut.edge_ranks();
  on_every_rank([&] {
    try {
      keep_on_top(net, std::vector<double>(net.vessel_count(), 1.0), forced, partition);
    } catch (const SettingError& e) {
      const auto kept = std::count(forced.begin(), forced.end(), std::uint8_t{1});
      throw SettingError(e.setting(), e.message() + " (the " + std::to_string(kept) +
                                          " vessels a wave travels in stay on one rank, with those above them)");
    }
    cut = tree_cut(net, partition);
  });
  const int rank = world_rank(), top = cut.top_rank;
  // Per vessel this rank hands the top: its index, flow and the pressure of its node below
  // (the node above is the top's already, or another moved vessel's below).
  std::vector<double> moved;
  SteadyFlow& s = distended.flow;
  if (rank != top)
    for (std::size_t c = 0; c < cut.parent_edge.size(); ++c) {
      const std::int32_t v = cut.parent_edge[c];
      if (v >= 0 && old_rank[static_cast<std::size_t>(v)] == rank && partition.rank_of_vessel[static_cast<std::size_t>(v)] == top)
        moved.insert(moved.end(), {static_cast<double>(v), s.flow[static_cast<std::size_t>(v)], static_cast<double>(c), s.node_pressure[c]});
    }
  int count = static_cast<int>(moved.size());
  std::vector<int> counts(static_cast<std::size_t>(world_size())), offsets(counts.size(), 0);
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, top, MPI_COMM_WORLD);
  for (std::size_t r = 1; r < counts.size(); ++r) offsets[r] = offsets[r - 1] + counts[r - 1];
  std::vector<double> all(rank == top ? static_cast<std::size_t>(offsets.back() + counts.back()) : 0);
  MPI_Gatherv(moved.data(), count, MPI_DOUBLE, all.data(), counts.data(), offsets.data(), MPI_DOUBLE, top, MPI_COMM_WORLD);
  for (std::size_t k = 0; k < all.size(); k += 4) {
    s.flow[static_cast<std::size_t>(all[k])] = all[k + 1];
    s.node_pressure[static_cast<std::size_t>(all[k + 2])] = all[k + 3];
  }
  distended.nodes = cut.held_nodes()[static_cast<std::size_t>(rank)];
  distended.nodes_by_label = distended.nodes;
  std::sort(distended.nodes_by_label.begin(), distended.nodes_by_label.end());
  distended.vessels.clear();
  for (const std::int32_t node : distended.nodes)
    if (const std::int32_t v = cut.parent_edge[static_cast<std::size_t>(node)]; v >= 0) distended.vessels.push_back(v);
}

// The forced vessels of every rank, known to every rank: a byte per vessel.
std::vector<std::uint8_t> forced_everywhere(const Network& net, const Blood& blood, std::span<const TubeLaw> laws,
                                            const ViscosityTable& viscosity, const DistendedOverRanks& distended,
                                            const std::function<bool(const VesselLine&)>& shift_source) {
  std::vector<std::int32_t> mine;  // every forced vessel of this rank
  on_every_rank([&] {
    for (const std::int32_t v : distended.vessels)
      if (shift_source(loaded_line(net, blood, laws, viscosity, distended.flow, static_cast<std::size_t>(v))))
        mine.push_back(v);
  });
  int count = static_cast<int>(mine.size());
  const int ranks = world_size();
  std::vector<int> counts(static_cast<std::size_t>(ranks)), offsets(static_cast<std::size_t>(ranks), 0);
  MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, MPI_COMM_WORLD);
  for (std::size_t r = 1; r < counts.size(); ++r) offsets[r] = offsets[r - 1] + counts[r - 1];
  std::vector<std::int32_t> all(static_cast<std::size_t>(offsets.back() + counts.back()));
  MPI_Allgatherv(mine.data(), count, MPI_INT32_T, all.data(), counts.data(), offsets.data(), MPI_INT32_T, MPI_COMM_WORLD);
  std::vector<std::uint8_t> forced(net.vessel_count(), 0);
  for (const std::int32_t v : all) forced[static_cast<std::size_t>(v)] = 1;
  return forced;
}

// Whether a forced vessel runs from the top's rank into another rank's share.
bool crosses(const TreeCut& cut, std::span<const std::uint8_t> forced) {
  for (int rank = 0; rank < cut.ranks; ++rank)
    if (rank != cut.top_rank)
      for (const std::int32_t r : cut.roots[static_cast<std::size_t>(rank)])
        if (forced[static_cast<std::size_t>(cut.parent_edge[static_cast<std::size_t>(r)])]) return true;
  return false;
}

// A tree fed by its inflow split: a pressure held at a node refused first (its harmonic system
// is not the cut's forest), on every rank alike.
std::pair<Partition, TreeCut> split_fed_tree(const Network& net, const RunBoundaries& boundaries) {
  on_every_rank([&] {
    for (std::size_t i = 0; i < boundaries.size(); ++i)
      if (boundaries.type(i) == BoundaryType::pressure)
        throw InputError("node " + std::to_string(net.node_id[static_cast<std::size_t>(boundaries.node(i))]) +
                         " holds a pressure: the periodic state over ranks takes a tree fed by its inflow into "
                         "outlets; run this network on one rank");
  });
  return split(net);
}

// A rank's part of a tree's periodic state over the ranks, set up: the vessels split (the
// forced ones, which `forced` gives once the distended state is known, and every vessel above
// them on the top), the distended state, the ghosts' steady state on the top, the distributed
// harmonic system and the HarmonicShare that solves with it. Built in place (the share's
// solve holds references to it).
struct RankHarmonics {
  using Forced = std::function<std::vector<std::uint8_t>(const DistendedOverRanks&)>;
  RankHarmonics(const Network& net, const Blood& blood, std::span<const TubeLaw> laws, const ViscosityTable& viscosity,
                int threads, const Forced& forced_of)
      : boundaries(net), split_(split_fed_tree(net, boundaries)), partition(std::move(split_.first)),
        cut(std::move(split_.second)) {
    const double inflow = net.inlet ? net.inlet->waveform.mean_value() : 0.0;
    distended = solve_distended_steady_flow_over_ranks(net, cut, blood, laws, viscosity, inflow, threads);
    if (forced_of) {
      const std::vector<std::uint8_t> forced = forced_of(distended);
      if (crosses(cut, forced)) keep_forced_on_top(net, forced, partition, cut, distended);
    }
    send_ghosts_to_top(cut, distended.flow);
    system.emplace(MPI_COMM_WORLD, cut);
    share.vessels = distended.vessels;
    std::sort(share.vessels.begin(), share.vessels.end());
    if (world_rank() == cut.top_rank) {
      for (int r = 0; r < cut.ranks; ++r)  // the vessels into the other ranks' shares
        if (r != cut.top_rank)
          for (const std::int32_t root : cut.roots[static_cast<std::size_t>(r)])
            share.ghosts.push_back(cut.parent_edge[static_cast<std::size_t>(root)]);
      std::sort(share.ghosts.begin(), share.ghosts.end());
    }
    const std::span<const std::int32_t> nodes = system->nodes();
    share.nodes.assign(nodes.begin(), nodes.end());
    shunt_here.resize(nodes.size());
    x_here.resize(nodes.size());
    edge_here.resize(nodes.size());
    share.solve = [this, &net, threads](double /*w: in the two-ports*/, std::span<const Complex> shunt, std::span<Complex> current,
                                        const std::function<TwoPort(std::size_t)>& two_port) {
      solve(net, threads, shunt, current, two_port);
    };
    share.on_every_share = [](const std::function<void()>& step) { on_every_rank(step); };
  }
  RankHarmonics(const RankHarmonics&) = delete;
  RankHarmonics& operator=(const RankHarmonics&) = delete;

  RunBoundaries boundaries;
 private:
  std::pair<Partition, TreeCut> split_;
 public:
  Partition partition;
  TreeCut cut;
  DistendedOverRanks distended;
  std::optional<MpiHarmonicTree> system;
  HarmonicShare share;

 private:
  std::vector<Complex> shunt_here, x_here;
  std::vector<EdgeToParent> edge_here;
  void solve(const Network& net, int threads, std::span<const Complex> shunt, std::span<Complex> current,
             const std::function<TwoPort(std::size_t)>& two_port) {
    const std::span<const std::int32_t> nodes = system->nodes();
    const auto count = static_cast<std::int64_t>(nodes.size());
#pragma omp parallel for schedule(static) num_threads(threads) if (threads > 1)
    for (std::int64_t k = 0; k < count; ++k) {
      const auto node = static_cast<std::size_t>(nodes[static_cast<std::size_t>(k)]);
      const std::int32_t v = cut.parent_edge[node];
      edge_here[static_cast<std::size_t>(k)] =
          v >= 0 ? EdgeToParent::of(two_port(static_cast<std::size_t>(v)),
                                    net.from[static_cast<std::size_t>(v)] == static_cast<std::int64_t>(node))
                 : EdgeToParent{};
    }
    for (std::size_t k = 0; k < nodes.size(); ++k) {
      shunt_here[k] = shunt[static_cast<std::size_t>(nodes[k])];
      x_here[k] = current[static_cast<std::size_t>(nodes[k])];
    }
    try {
      system->solve(shunt_here, edge_here, x_here);
    } catch (const Collective<std::invalid_argument>& e) {  // every rank alike
      if (std::string(e.what()).find("no admittance to ground") == std::string::npos) throw;
      throw Collective<InputError>("the linear periodic solution: a part of the network has no path to an outlet or a pressure");
    }
    for (std::size_t k = 0; k < nodes.size(); ++k) current[static_cast<std::size_t>(nodes[k])] = x_here[k];
    for (std::size_t k = 0; k < system->root_parents().size(); ++k)
      current[static_cast<std::size_t>(system->root_parents()[k])] = system->root_parent_potentials()[k];
    for (std::size_t k = 0; k < system->share_roots().size(); ++k)
      current[static_cast<std::size_t>(system->share_roots()[k])] = system->share_root_potentials()[k];
  }
};

// Where each rank's results are: each vessel's rank, and for rank 0's gather (on rank 0 alone)
// per rank its vessels (increasing) and its nodes (in the order its results list them).
void place_results(LinearPeriodicOverRanks& out, const std::vector<std::int32_t>& vessel_rank,
                   std::vector<std::vector<std::int32_t>> nodes_of) {
  out.vessel_rank = vessel_rank;
  if (world_rank() != 0) return;
  out.vessels_of.assign(nodes_of.size(), {});
  for (std::size_t v = 0; v < vessel_rank.size(); ++v)
    out.vessels_of[static_cast<std::size_t>(vessel_rank[v])].push_back(static_cast<std::int32_t>(v));
  out.nodes_of = std::move(nodes_of);
}

// A network with loops or pressures held at nodes, or a tree whose cut cannot be made: the
// vessels split by METIS (a tree's by subtrees), every rank the whole distended steady state
// (as every rank holds the whole network) and the lines of every vessel (its own answered,
// the others' ghosts), and each harmonic's system assembled over the ranks and solved by
// PETSc (petsc_harmonic_network.hpp): only the solves and the results are divided, for now.
LinearPeriodicOverRanks solve_on_graph(const Network& net, const Blood& blood, std::span<const TubeLaw> laws,
                                       const ViscosityTable& viscosity, int harmonics, int threads,
                                       const std::function<bool(const VesselLine&)>& shift_source) {
  const int ranks = world_size(), rank = world_rank();
  const std::size_t n = net.vessel_count(), nodes = net.node_count();
  const RunBoundaries boundaries(net);
  Partition partition;
  std::vector<std::int32_t> node_owner;
  SteadyFlow steady;
  on_every_rank([&] {
    partition = partition_network(net, std::vector<double>(n, 1.0), ranks);
    node_owner = node_owners(net, partition);
    steady = solve_distended_steady_flow(net, blood, laws, viscosity, net.inlet ? net.inlet->waveform.mean_value() : 0.0,
                                         nullptr, threads);
  });
  check_one_partition(partition);
  HarmonicShare share;
  for (std::size_t v = 0; v < n; ++v)
    if (partition.rank_of_vessel[v] == rank) share.vessels.push_back(static_cast<std::int32_t>(v));
  for (std::size_t i = 0; i < nodes; ++i)
    if (node_owner[i] == rank) share.nodes.push_back(static_cast<std::int32_t>(i));
  // Every other vessel a ghost: each rank holds the whole network's lines, so that the mean
  // shift of a vessel a wave travels in finds its ends' neighbours whatever rank they are on.
  for (std::size_t v = 0; v < n; ++v)
    if (partition.rank_of_vessel[v] != rank) share.ghosts.push_back(static_cast<std::int32_t>(v));
  share.holds_every_vessel = true;
  PetscHarmonicNetwork system(nodes, net.from, net.to, node_owner, partition.rank_of_vessel, net.node_id);
  std::vector<TwoPort> two_ports(n);
  std::vector<Complex> potential(nodes);
  share.solve = [&](double, std::span<const Complex> shunt, std::span<Complex> current,
                    const std::function<TwoPort(std::size_t)>& two_port) {
    for (const std::int32_t v : share.vessels) two_ports[static_cast<std::size_t>(v)] = two_port(static_cast<std::size_t>(v));
    system.solve(two_ports, shunt, current, potential);
    std::copy(potential.begin(), potential.end(), current.begin());
  };
  share.on_every_share = [](const std::function<void()>& step) { on_every_rank(step); };
  LinearPeriodicOverRanks out;
  out.periodic = solve_linear_periodic(net, blood, laws, viscosity, steady, boundaries, harmonics, threads, shift_source, share);
  out.vessels = share.vessels;
  out.nodes = share.nodes;
  std::vector<std::vector<std::int32_t>> nodes_of(rank == 0 ? static_cast<std::size_t>(ranks) : 0);
  for (std::size_t i = 0; i < nodes && rank == 0; ++i)
    nodes_of[static_cast<std::size_t>(node_owner[i])].push_back(static_cast<std::int32_t>(i));
  place_results(out, partition.rank_of_vessel, std::move(nodes_of));
  out.partition = std::move(partition);
  out.solver = "every harmonic's nodal system by PETSc's " + system.method();
  return out;
}

// Whether the linear periodic state over ranks needs the graph's solve: loops, or a pressure
// held at a node (a tree's distributed elimination takes a tree fed by its inflow).
bool needs_graph_solve(const Network& net) {
  const RunBoundaries boundaries(net);
  for (std::size_t i = 0; i < boundaries.size(); ++i)
    if (boundaries.type(i) == BoundaryType::pressure) return true;
  return !is_forest(net);
}

// A tree fed by its inflow: the distributed elimination of each harmonic (RankHarmonics).
LinearPeriodicOverRanks solve_on_tree(const Network& net, const Blood& blood, std::span<const TubeLaw> laws,
                                      const ViscosityTable& viscosity, int harmonics, int threads,
                                      const std::function<bool(const VesselLine&)>& shift_source) {
  RankHarmonics::Forced forced;
  if (shift_source)
    forced = [&](const DistendedOverRanks& d) { return forced_everywhere(net, blood, laws, viscosity, d, shift_source); };
  const auto rank = std::make_unique<RankHarmonics>(net, blood, laws, viscosity, threads, forced);
  LinearPeriodic periodic = solve_linear_periodic(net, blood, laws, viscosity, rank->distended.flow, rank->boundaries,
                                                  harmonics, threads, shift_source, rank->share);
  LinearPeriodicOverRanks out;
  out.periodic = std::move(periodic);
  out.vessels = rank->share.vessels;
  out.nodes = rank->share.nodes;
  out.partition = std::move(rank->partition);
  out.cut = std::move(rank->cut);
  out.traffic = rank->system->traffic();
  // The results by the cut: a rank's nodes as it holds them, its vessels their edges to their parents.
  place_results(out, out.cut->edge_ranks(), world_rank() == 0 ? out.cut->held_nodes() : std::vector<std::vector<std::int32_t>>{});
  const RootExchange::Traffic& t = out.traffic;
  out.solver = "the harmonics' exchanges on rank 0: " + std::to_string(t.calls) + " collective calls, " +
               std::to_string(t.bytes) + " bytes, " + format_quantity(t.seconds, "s");
  return out;
}

}  // namespace

LinearPeriodicOverRanks solve_linear_periodic_over_ranks(const Network& net, const Blood& blood,
                                                         std::span<const TubeLaw> laws, const ViscosityTable& viscosity,
                                                         int harmonics, int threads,
                                                         const std::function<bool(const VesselLine&)>& shift_source) {
  if (!needs_graph_solve(net)) {
    try {
      return solve_on_tree(net, blood, laws, viscosity, harmonics, threads, shift_source);
    } catch (const Collective<SettingError>& e) {
      // A tree whose cut cannot be made (its top spread over the ranks, or the vessels a wave
      // travels in leaving a rank empty on the top: ADAN56): every rank alike, the graph's solve.
      if (e.setting() != "ranks") throw;
    }
  }
  return solve_on_graph(net, blood, laws, viscosity, harmonics, threads, shift_source);
}

PeriodicInstantOverRanks solve_periodic_instant_over_ranks(const Network& net, const Blood& blood,
                                                           std::span<const TubeLaw> laws, const ViscosityTable& viscosity,
                                                           int harmonics, double time, const std::vector<bool>& keep,
                                                           int threads, bool shift_mean) {
  const RankHarmonics::Forced forced = [&](const DistendedOverRanks&) {
    std::vector<std::uint8_t> bytes(keep.begin(), keep.end());
    return bytes;
  };
  const auto rank = std::make_unique<RankHarmonics>(net, blood, laws, viscosity, threads, forced);
  PeriodicInstant instant = solve_periodic_instant(net, blood, laws, viscosity, rank->distended.flow, rank->boundaries,
                                                   harmonics, time, keep, threads, shift_mean, rank->share);
  return {std::move(instant), rank->share.vessels, rank->share.nodes, std::move(rank->partition), std::move(rank->cut)};
}

}  // namespace hemotree
