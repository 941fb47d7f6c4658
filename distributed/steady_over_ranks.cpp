#include "distributed/steady_over_ranks.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include "core/setting_error.hpp"
#include "core/units.hpp"
#include "distributed/gather_rows.hpp"
#include "distributed/network_cut.hpp"
#include "distributed/petsc_flow_network.hpp"
#include "distributed/steady_share.hpp"
#include "mpi/session.hpp"
#include "partition/partition.hpp"

namespace hemotree {

namespace {

// Any other network (loops, pressures prescribed at nodes): PETSc's solve of the nodal system
// over the ranks, each node on the rank of a vessel leaving it (METIS's pieces go with their
// `from` nodes), else of one entering it; the pressures on every rank, the flows on rank 0
// as the one-process solve forms them.
SteadyOverRanks solve_by_petsc(const Network& net, const Blood& blood, std::span<const double> hematocrit,
                               double inlet_flow, const SteadyRows& rows, const Partition& partition) {
  const std::size_t n = net.vessel_count(), nodes = net.node_count();
  std::vector<std::int32_t> owner(nodes, -1);
  std::vector<double> resistance(n), conductance(n), inflow;
  on_every_rank([&] {
    for (std::size_t v = 0; v < n; ++v) owner[static_cast<std::size_t>(net.from[v])] = partition.rank_of_vessel[v];
    for (std::size_t v = 0; v < n; ++v)
      if (std::int32_t& o = owner[static_cast<std::size_t>(net.to[v])]; o < 0) o = partition.rank_of_vessel[v];
    for (std::int32_t& o : owner) o = std::max(o, 0);  // a node no vessel touches: a unit shunt, rank 0's
    for (std::size_t v = 0; v < n; ++v) {
      resistance[v] = vessel_resistance(net, blood, v, hematocrit);
      conductance[v] = 1 / resistance[v];
    }
    inflow = rows.inflow;
    if (rows.inlet_node >= 0) inflow[static_cast<std::size_t>(rows.inlet_node)] += inlet_flow;
  });
  SteadyOverRanks out{{}, describe(partition)};
  std::vector<double> pressure = rows.pressure;
  PetscFlowNetwork system(nodes, net.from, net.to, rows.prescribed, owner);
  system.solve(conductance, rows.shunt, inflow, pressure);
  out.partition += "; PETSc's " + system.method() + " in " + std::to_string(system.iterations()) + " iterations";
  if (world_rank() != 0) return out;
  SteadyFlow& s = out.flow;
  s.node_pressure = std::move(pressure);
  s.flow.resize(n);
  for (std::size_t v = 0; v < n; ++v)
    s.flow[v] = (s.node_pressure[static_cast<std::size_t>(net.from[v])] - s.node_pressure[static_cast<std::size_t>(net.to[v])]) /
                resistance[v];
  s.inlet_pressure = rows.inlet_node >= 0 ? s.node_pressure[static_cast<std::size_t>(rows.inlet_node)]
                                          : std::numeric_limits<double>::quiet_NaN();
  return out;
}

}  // namespace

SteadyOverRanks solve_steady_flow_over_ranks(const Network& net, const Blood& blood, double inlet_flow,
                                             std::span<const double> hematocrit) {
  const int ranks = world_size(), rank = world_rank();
  // What each rank sets up alone, its failure every rank's before any of them solves.
  SteadyRows rows;
  Partition partition;
  bool iterative = false;
  std::optional<TreeCut> cut;
  on_every_rank([&] {
    rows = steady_rows(net);  // its checks on every rank alike
    partition = partition_network(net, std::vector<double>(net.vessel_count(), 1.0), ranks);
    iterative = partition.method == Partition::Method::metis ||
                std::any_of(rows.prescribed.begin(), rows.prescribed.end(), [](unsigned char p) { return p != 0; });
    // Rank 0 gathers a pressure and a flow a node, counted in MPI's ints.
    if (2 * net.node_count() > static_cast<std::size_t>(std::numeric_limits<int>::max()))
      throw SettingError("ranks", placeholder("ranks") + ": " + std::to_string(net.node_count()) +
                                      " nodes are more than the gathering of the results on one rank takes yet");
    if (iterative) return;
    // A tree whose node labels hang it from another node than its inlet (the nodal system's
    // elimination starts at its lowest label) is not cut into subtrees of that elimination by
    // the partition's flow subtrees: PETSc solves it instead (vgen's and vprune's labels start
    // at the inlet).
    if (!partition.top_spread && partition.top_rank >= 0) {
      try {
        cut.emplace(tree_cut(net, partition));
      } catch (const SettingError&) {
        iterative = true;
      }
    } else {
      cut.emplace(tree_cut(net, partition));  // refused, in words
    }
  });
  check_one_partition(partition);
  if (iterative) return solve_by_petsc(net, blood, hematocrit, inlet_flow, rows, partition);

  // This rank's share and its vessels' resistances (rigid), one solve.
  std::optional<SteadyShare> share;
  std::vector<double> resistance(net.vessel_count(), 0.0);
  on_every_rank([&] {
    share.emplace(net, *cut, rows, inlet_flow);
    for (const std::int32_t v : share->vessels())
      resistance[static_cast<std::size_t>(v)] = vessel_resistance(net, blood, static_cast<std::size_t>(v), hematocrit);
  });
  SteadyFlow held_here;
  share->solve(resistance, held_here);
  // Per node of this rank, its pressure and the flow of its vessel to its parent.
  const std::span<const std::int32_t> nodes = share->nodes();
  std::vector<double> mine(2 * nodes.size());
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    const auto node = static_cast<std::size_t>(nodes[k]);
    mine[2 * k] = held_here.node_pressure[node];
    const std::int32_t v = cut->parent_edge[node];
    mine[2 * k + 1] = v >= 0 ? held_here.flow[static_cast<std::size_t>(v)] : 0.0;
  }
  const MpiTreeSystem::Traffic& traffic = share->traffic();
  SteadyOverRanks out{{}, describe(partition) + "; the tree's exchange on rank 0: " + std::to_string(traffic.calls) +
                              " collective calls, " + std::to_string(traffic.bytes) + " bytes, " +
                              format_quantity(traffic.seconds, "s")};
  // Gathered on rank 0, each rank's nodes as it holds them.
  SteadyFlow& s = out.flow;
  if (rank == 0) {
    s.node_pressure.assign(net.node_count(), 0.0);
    s.flow.assign(net.vessel_count(), 0.0);
  }
  gather_rows(mine, 2, rank == 0 ? cut->held_nodes() : std::vector<std::vector<std::int32_t>>{}, net.node_count(),
              [&](std::int32_t node, const double* row) {
                s.node_pressure[static_cast<std::size_t>(node)] = row[0];
                if (const std::int32_t v = cut->parent_edge[static_cast<std::size_t>(node)]; v >= 0)
                  s.flow[static_cast<std::size_t>(v)] = row[1];
              });
  if (rank != 0) return out;
  s.inlet_pressure = rows.inlet_node >= 0 ? s.node_pressure[static_cast<std::size_t>(rows.inlet_node)]
                                          : std::numeric_limits<double>::quiet_NaN();
  return out;
}

}  // namespace hemotree
