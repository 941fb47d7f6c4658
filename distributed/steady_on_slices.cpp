#include "distributed/steady_on_slices.hpp"

#include <algorithm>
#include <cstdint>
#include <vector>

#include "distributed/network_cut.hpp"
#include "distributed/steady_share.hpp"
#include "mpi/session.hpp"
#include "steady/steady_flow.hpp"

namespace hemotree {

// This rank's share of the system, and per node it holds the slice's vessel to its parent.
struct SteadyFlowOnSlices::Share {
  std::optional<SteadyShare> system;
  std::vector<std::int32_t> parent_vessel;  // per node of system->nodes(): its slice vessel, -1 at a root
  std::vector<std::int32_t> node_place;     // per node of system->nodes(): its slice node, -1 where none
  std::vector<std::int32_t> root_parent_place;  // per share root's parent (system->root_parents()): its slice node
  std::vector<std::vector<std::int32_t>> held_lists;  // on rank 0: every rank's nodes, as it holds them
};

SteadyFlowOnSlices::SteadyFlowOnSlices(const Network& held, const std::string& path,
                                       const std::function<Blood(const Network&)>& blood_of)
    : share_(std::make_unique<Share>()) {
  const int ranks = world_size(), rank = world_rank();
  // The topology, the partition and the cut, each rank's own and the same on every rank;
  // rank 0 checks the whole network first, as the plain command does.
  Network lead_topology;
  on_every_rank([&] {
    if (rank == 0) {
      lead_inlet_node_ = steady_rows(held).inlet_node;
      lead_topology = topology_of(held);
    }
  });
  const Network& topology = rank == 0 ? lead_topology : held;
  vessel_count_ = topology.vessel_count();
  blood_ = blood_of(topology);
  on_every_rank([&] {
    check_gathered_nodes(topology.node_count());
    if (!topology.boundaries.empty()) return;  // boundaries at nodes: PETSc's solve
    partition_ = partition_network(topology, std::vector<double>(topology.vessel_count(), 1.0), ranks);
    cut_ = steady_tree_cut(topology, partition_);
  });
  check_one_partition(partition_);
  if (!cut_) return;

  // This rank's nodes (its share's, and the top's on the top's rank), the vessels to their
  // parents, and its slice: those vessels' rows and the nodes they touch.
  const double inlet_flow = topology.inlet ? topology.inlet->waveform.mean_value() : 0.0;
  const std::int64_t inlet_node =
      topology.inlet ? topology.from[static_cast<std::size_t>(topology.index_of(topology.inlet->vessel))] : -1;
  on_every_rank([&] {
    std::vector<std::int32_t> nodes = cut_->share_nodes(rank);
    if (rank == cut_->top_rank) {
      const std::vector<std::int32_t> top = cut_->top_nodes();
      nodes.insert(nodes.end(), top.begin(), top.end());
    }
    std::vector<std::int32_t> vessels;
    for (const std::int32_t node : nodes)
      if (const std::int32_t v = cut_->parent_edge[static_cast<std::size_t>(node)]; v >= 0) vessels.push_back(v);
    std::sort(vessels.begin(), vessels.end());
    slice_ = rank == 0 ? slice_of(held, vessels) : read_network_slice(path, topology, vessels);
    // A node no vessel touches carries nothing: a unit shunt holds it at 0 Pa (steady_rows).
    std::vector<std::uint8_t> touched(topology.node_count(), 0);
    for (std::size_t v = 0; v < topology.vessel_count(); ++v)
      touched[static_cast<std::size_t>(topology.from[v])] = touched[static_cast<std::size_t>(topology.to[v])] = 1;
    const SteadyRows rows = boundary_rows(slice_.net);
    share_->system.emplace(topology, *cut_, [&](std::int32_t node) {
      SteadyShare::Row r{touched[static_cast<std::size_t>(node)] ? 0.0 : 1.0, 0.0};
      if (const std::int32_t i = slice_.node_at(node); i >= 0)
        r = {rows.shunt[static_cast<std::size_t>(i)], rows.inflow[static_cast<std::size_t>(i)]};
      if (node == inlet_node) r.inflow += inlet_flow;
      return r;
    });
    for (const std::int32_t node : share_->system->root_parents()) share_->root_parent_place.push_back(slice_.node_at(node));
    for (const std::int32_t node : share_->system->nodes()) {
      share_->node_place.push_back(slice_.node_at(node));
      const std::int32_t v = cut_->parent_edge[static_cast<std::size_t>(node)];
      share_->parent_vessel.push_back(
          v < 0 ? -1
                : static_cast<std::int32_t>(std::lower_bound(slice_.vessel_row.begin(), slice_.vessel_row.end(), v) -
                                            slice_.vessel_row.begin()));
    }
  });
}

SteadyFlowOnSlices::~SteadyFlowOnSlices() = default;

SteadyOverRanks SteadyFlowOnSlices::solve(std::span<const double> hematocrit) {
  SteadyShare& share = *share_->system;
  const std::vector<std::int32_t>& parent_vessel = share_->parent_vessel;
  const std::span<const std::int32_t> nodes = share.nodes();
  // Each node's conductance to its parent, 1 / R as the one-process system takes it.
  std::vector<double> resistance(slice_.net.vessel_count()), conductance(nodes.size(), 0.0);
  on_every_rank([&] {
    for (std::size_t k = 0; k < resistance.size(); ++k) resistance[k] = vessel_resistance(slice_.net, blood_, k, hematocrit);
  });
  for (std::size_t k = 0; k < nodes.size(); ++k)
    if (parent_vessel[k] >= 0) conductance[k] = 1 / resistance[static_cast<std::size_t>(parent_vessel[k])];
  const std::span<const double> x = share.solve_nodes(conductance);

  // Per node held, its pressure and the flow of its edge to its parent: the ends' pressures
  // (its own, its parent's: held here, or a share root's parent on the top) over the edge's
  // resistance, as the whole network's solve forms them.
  std::vector<double> pressure(slice_.net.node_count(), 0.0);
  for (std::size_t k = 0; k < nodes.size(); ++k)
    if (const std::int32_t i = share_->node_place[k]; i >= 0) pressure[static_cast<std::size_t>(i)] = x[k];
  for (std::size_t k = 0; k < share.root_parents().size(); ++k)
    if (const std::int32_t i = share_->root_parent_place[k]; i >= 0)
      pressure[static_cast<std::size_t>(i)] = share.root_parent_pressures()[k];
  std::vector<double> mine(2 * nodes.size());
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    mine[2 * k] = x[k];
    if (parent_vessel[k] < 0) continue;
    const auto j = static_cast<std::size_t>(parent_vessel[k]);
    mine[2 * k + 1] = (pressure[static_cast<std::size_t>(slice_.net.from[j])] - pressure[static_cast<std::size_t>(slice_.net.to[j])]) /
                      resistance[j];
  }
  return gather_tree_flow(*cut_, partition_, "each rank its slice of the network", share.traffic(), mine,
                          vessel_count_, lead_inlet_node_, share_->held_lists);
}

}  // namespace hemotree
