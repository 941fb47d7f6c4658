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

void check_gathered_nodes(std::size_t nodes) {
  // Rank 0 gathers a pressure and a flow a node, counted in MPI's ints.
  if (2 * nodes > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    throw SettingError("ranks", placeholder("ranks") + ": " + std::to_string(nodes) +
                                    " nodes are more than the gathering of the results on one rank takes yet");
}

SteadyFlowOverRanks::SteadyFlowOverRanks(const Network& net, const Blood& blood, double inlet_flow)
    : net_(net), blood_(blood) {
  const int ranks = world_size();
  // What each rank sets up alone, its failure every rank's before any of them solves.
  bool iterative = false;
  on_every_rank([&] {
    rows_ = steady_rows(net);  // its checks on every rank alike
    partition_ = partition_network(net, std::vector<double>(net.vessel_count(), 1.0), ranks);
    check_gathered_nodes(net.node_count());
    if (std::none_of(rows_.prescribed.begin(), rows_.prescribed.end(), [](unsigned char p) { return p != 0; }))
      cut_ = steady_tree_cut(net, partition_);
    iterative = !cut_;
  });
  check_one_partition(partition_);
  if (iterative) {
    std::vector<std::int32_t> owner;
    on_every_rank([&] {
      owner = node_owners(net, partition_);
      inflow_ = rows_.inflow;
      if (rows_.inlet_node >= 0) inflow_[static_cast<std::size_t>(rows_.inlet_node)] += inlet_flow;
    });
    petsc_ = std::make_unique<PetscFlowNetwork>(net.node_count(), net.from, net.to, rows_.prescribed, owner);
    return;
  }
  on_every_rank([&] { share_.emplace(net, *cut_, rows_, inlet_flow); });
}

SteadyFlowOverRanks::~SteadyFlowOverRanks() = default;

SteadyOverRanks SteadyFlowOverRanks::solve(std::span<const double> hematocrit) {
  return petsc_ ? solve_by_petsc(hematocrit) : solve_tree(hematocrit);
}

// Any other network (loops, pressures prescribed at nodes): PETSc's solve of the nodal system
// over the ranks; the pressures on every rank, the flows on rank 0 as the one-process solve
// forms them.
SteadyOverRanks SteadyFlowOverRanks::solve_by_petsc(std::span<const double> hematocrit) {
  const Network& net = net_;
  const std::size_t n = net.vessel_count();
  std::vector<double> resistance(n), conductance(n);
  on_every_rank([&] {
    for (std::size_t v = 0; v < n; ++v) {
      resistance[v] = vessel_resistance(net, blood_, v, hematocrit);
      conductance[v] = 1 / resistance[v];
    }
  });
  SteadyOverRanks out{{}, describe(partition_) + "; every rank holds the whole network"};
  std::vector<double> pressure = rows_.pressure;
  petsc_->solve(conductance, rows_.shunt, inflow_, pressure);
  out.partition += "; PETSc's " + petsc_->method() + " in " + std::to_string(petsc_->iterations()) + " iterations";
  if (world_rank() != 0) return out;
  SteadyFlow& s = out.flow;
  s.node_pressure = std::move(pressure);
  s.flow.resize(n);
  for (std::size_t v = 0; v < n; ++v)
    s.flow[v] = (s.node_pressure[static_cast<std::size_t>(net.from[v])] - s.node_pressure[static_cast<std::size_t>(net.to[v])]) /
                resistance[v];
  s.inlet_pressure = rows_.inlet_node >= 0 ? s.node_pressure[static_cast<std::size_t>(rows_.inlet_node)]
                                           : std::numeric_limits<double>::quiet_NaN();
  return out;
}

// A tree: this rank's vessels' resistances, one distributed solve, gathered on rank 0.
SteadyOverRanks SteadyFlowOverRanks::solve_tree(std::span<const double> hematocrit) {
  const Network& net = net_;
  on_every_rank([&] {
    if (resistance_.size() != net.vessel_count()) resistance_.assign(net.vessel_count(), 0.0);
    for (const std::int32_t v : share_->vessels())
      resistance_[static_cast<std::size_t>(v)] = vessel_resistance(net, blood_, static_cast<std::size_t>(v), hematocrit);
  });
  SteadyFlow held_here;
  share_->solve(resistance_, held_here);
  // Per node of this rank, its pressure and the flow of its vessel to its parent.
  const std::span<const std::int32_t> nodes = share_->nodes();
  std::vector<double> mine(2 * nodes.size());
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    const auto node = static_cast<std::size_t>(nodes[k]);
    mine[2 * k] = held_here.node_pressure[node];
    const std::int32_t v = cut_->parent_edge[node];
    mine[2 * k + 1] = v >= 0 ? held_here.flow[static_cast<std::size_t>(v)] : 0.0;
  }
  return gather_tree_flow(*cut_, partition_, "every rank holds the whole network", share_->traffic(), mine,
                          net.vessel_count(), rows_.inlet_node, held_lists_);
}

SteadyOverRanks gather_tree_flow(const TreeCut& cut, const Partition& partition, const char* holding,
                                 const MpiTreeSystem::Traffic& traffic, std::span<const double> rows,
                                 std::size_t vessels, std::int64_t inlet_node,
                                 std::vector<std::vector<std::int32_t>>& held_lists) {
  const int rank = world_rank();
  const std::size_t nodes = cut.parent_edge.size();
  SteadyOverRanks out{{}, describe(partition) + "; " + holding + "; the tree's exchange on rank 0: " +
                              std::to_string(traffic.calls) + " collective calls, " + std::to_string(traffic.bytes) +
                              " bytes, " + format_quantity(traffic.seconds, "s")};
  // Gathered on rank 0, each rank's nodes as it holds them.
  SteadyFlow& s = out.flow;
  if (rank == 0) {
    s.node_pressure.assign(nodes, 0.0);
    s.flow.assign(vessels, 0.0);
    if (held_lists.empty()) held_lists = cut.held_nodes();
  }
  gather_rows(rows, 2, held_lists, nodes, [&](std::int32_t node, const double* row) {
    s.node_pressure[static_cast<std::size_t>(node)] = row[0];
    if (const std::int32_t v = cut.parent_edge[static_cast<std::size_t>(node)]; v >= 0)
      s.flow[static_cast<std::size_t>(v)] = row[1];
  });
  if (rank != 0) return out;
  s.inlet_pressure = inlet_node >= 0 ? s.node_pressure[static_cast<std::size_t>(inlet_node)]
                                     : std::numeric_limits<double>::quiet_NaN();
  return out;
}

SteadyOverRanks solve_steady_flow_over_ranks(const Network& net, const Blood& blood, double inlet_flow,
                                             std::span<const double> hematocrit) {
  return SteadyFlowOverRanks(net, blood, inlet_flow).solve(hematocrit);
}

}  // namespace hemotree
