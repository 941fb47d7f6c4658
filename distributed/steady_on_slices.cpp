#include "distributed/steady_on_slices.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/setting_error.hpp"
#include "core/units.hpp"
#include "distributed/gather_rows.hpp"
#include "distributed/network_cut.hpp"
#include "distributed/steady_share.hpp"
#include "formats/network_slice.hpp"
#include "mpi/session.hpp"
#include "partition/partition.hpp"
#include "steady/steady_flow.hpp"

namespace hemotree {

std::optional<SteadyOverRanks> solve_steady_flow_on_slices(const Network& held, const std::string& path,
                                                           const std::function<Blood(const Network&)>& blood_of) {
  const int ranks = world_size(), rank = world_rank();
  // The topology, the partition and the cut, each rank's own and the same on every rank;
  // rank 0 checks the whole network first, as the plain command does.
  const Network& lead = held;  // rank 0's
  Network lead_topology;
  Partition partition;
  std::optional<TreeCut> cut;
  std::int64_t lead_inlet_node = -1;  // rank 0's: the inlet's node, given or found by the checks
  on_every_rank([&] {
    if (rank == 0) {
      lead_inlet_node = steady_rows(lead).inlet_node;
      lead_topology = topology_of(lead);
    }
  });
  const Network& topology = rank == 0 ? lead_topology : held;
  on_every_rank([&] {
    check_gathered_nodes(topology.node_count());
    if (!topology.boundaries.empty()) return;  // boundaries at nodes: PETSc's solve
    partition = partition_network(topology, std::vector<double>(topology.vessel_count(), 1.0), ranks);
    cut = steady_tree_cut(topology, partition);
  });
  check_one_partition(partition);
  if (!cut) return std::nullopt;

  // This rank's nodes (its share's, and the top's on the top's rank), the vessels to their
  // parents, and its slice: those vessels' rows and the nodes they touch.
  const Blood blood = blood_of(topology);
  const double inlet_flow = topology.inlet ? topology.inlet->waveform.mean_value() : 0.0;
  const std::int64_t inlet_node =
      topology.inlet ? topology.from[static_cast<std::size_t>(topology.index_of(topology.inlet->vessel))] : -1;
  NetworkSlice slice;
  std::optional<SteadyShare> share;
  std::vector<double> conductance, resistance;  // per node held (its edge to its parent), per vessel of the slice
  on_every_rank([&] {
    std::vector<std::int32_t> held = cut->share_nodes(rank);
    if (rank == cut->top_rank) {
      const std::vector<std::int32_t> top = cut->top_nodes();
      held.insert(held.end(), top.begin(), top.end());
    }
    std::vector<std::int32_t> vessels;
    for (const std::int32_t node : held)
      if (const std::int32_t v = cut->parent_edge[static_cast<std::size_t>(node)]; v >= 0) vessels.push_back(v);
    std::sort(vessels.begin(), vessels.end());
    slice = rank == 0 ? slice_of(lead, vessels) : read_network_slice(path, topology, vessels);
    // A node no vessel touches carries nothing: a unit shunt holds it at 0 Pa (steady_rows).
    std::vector<std::uint8_t> touched(topology.node_count(), 0);
    for (std::size_t v = 0; v < topology.vessel_count(); ++v)
      touched[static_cast<std::size_t>(topology.from[v])] = touched[static_cast<std::size_t>(topology.to[v])] = 1;
    const SteadyRows rows = boundary_rows(slice.net);
    share.emplace(topology, *cut, [&](std::int32_t node) {
      SteadyShare::Row r{touched[static_cast<std::size_t>(node)] ? 0.0 : 1.0, 0.0};
      if (const std::int32_t i = slice.node_at(node); i >= 0)
        r = {rows.shunt[static_cast<std::size_t>(i)], rows.inflow[static_cast<std::size_t>(i)]};
      if (node == inlet_node) r.inflow += inlet_flow;
      return r;
    });
    resistance.resize(slice.net.vessel_count());
    for (std::size_t k = 0; k < resistance.size(); ++k) resistance[k] = vessel_resistance(slice.net, blood, k);
    for (const std::int32_t node : share->nodes()) {
      const std::int32_t v = cut->parent_edge[static_cast<std::size_t>(node)];
      conductance.push_back(v >= 0 ? 1 / resistance[static_cast<std::size_t>(
                                             std::lower_bound(slice.vessel_row.begin(), slice.vessel_row.end(), v) -
                                             slice.vessel_row.begin())]
                                   : 0.0);
    }
  });
  const std::span<const double> x = share->solve_nodes(conductance);

  // Per node held, its pressure and the flow of its edge to its parent: the ends' pressures
  // (its own, its parent's: held here, or a share root's parent on the top) over the edge's
  // resistance, as the whole network's solve forms them.
  const std::span<const std::int32_t> nodes = share->nodes();
  std::vector<double> pressure(slice.net.node_count(), 0.0);
  for (std::size_t k = 0; k < nodes.size(); ++k)
    if (const std::int32_t i = slice.node_at(nodes[k]); i >= 0) pressure[static_cast<std::size_t>(i)] = x[k];
  for (std::size_t k = 0; k < share->root_parents().size(); ++k)
    if (const std::int32_t i = slice.node_at(share->root_parents()[k]); i >= 0)
      pressure[static_cast<std::size_t>(i)] = share->root_parent_pressures()[k];
  std::vector<double> mine(2 * nodes.size());
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    mine[2 * k] = x[k];
    const std::int32_t v = cut->parent_edge[static_cast<std::size_t>(nodes[k])];
    if (v < 0) continue;
    const auto j = static_cast<std::size_t>(std::lower_bound(slice.vessel_row.begin(), slice.vessel_row.end(), v) -
                                            slice.vessel_row.begin());
    mine[2 * k + 1] = (pressure[static_cast<std::size_t>(slice.net.from[j])] - pressure[static_cast<std::size_t>(slice.net.to[j])]) /
                      resistance[j];
  }
  const MpiTreeSystem::Traffic& traffic = share->traffic();
  SteadyOverRanks out{{}, describe(partition) + "; each rank its slice of the network; the tree's exchange on rank 0: " +
                              std::to_string(traffic.calls) + " collective calls, " + std::to_string(traffic.bytes) +
                              " bytes, " + format_quantity(traffic.seconds, "s")};
  SteadyFlow& s = out.flow;
  if (rank == 0) {
    s.node_pressure.assign(topology.node_count(), 0.0);
    s.flow.assign(topology.vessel_count(), 0.0);
  }
  gather_rows(mine, 2, rank == 0 ? cut->held_nodes() : std::vector<std::vector<std::int32_t>>{}, topology.node_count(),
              [&](std::int32_t node, const double* row) {
                s.node_pressure[static_cast<std::size_t>(node)] = row[0];
                if (const std::int32_t v = cut->parent_edge[static_cast<std::size_t>(node)]; v >= 0)
                  s.flow[static_cast<std::size_t>(v)] = row[1];
              });
  if (rank != 0) return out;
  s.inlet_pressure = lead_inlet_node >= 0 ? s.node_pressure[static_cast<std::size_t>(lead_inlet_node)]
                                          : std::numeric_limits<double>::quiet_NaN();
  return out;
}

}  // namespace hemotree
