#include "distributed/distended_over_ranks.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include <mpi.h>

#include "distributed/mpi_tree_system.hpp"
#include "distributed/network_cut.hpp"
#include "mpi/session.hpp"
#include "steady/distended_iteration.hpp"

namespace hemotree {

DistendedOverRanks solve_distended_steady_flow_over_ranks(const Network& net, const TreeCut& cut, const Blood& blood,
                                                         std::span<const TubeLaw> laws, const ViscosityTable& viscosity,
                                                         double inlet_flow, int threads) {
  DistendedOverRanks out;
  std::optional<MpiTreeSystem> system;
  SteadyRows rows;
  std::vector<double> shunt, b, conductance, x;
  // What each rank sets up alone: its share's nodes and vessels, rows and rigid resistances.
  on_every_rank([&] {
    rows = steady_rows(net);
    system.emplace(MPI_COMM_WORLD, cut);
    out.nodes.assign(system->nodes().begin(), system->nodes().end());
    out.resistance.assign(net.vessel_count(), 0.0);
    for (const std::int32_t node : out.nodes) {
      const std::int32_t v = cut.parent_edge[static_cast<std::size_t>(node)];
      shunt.push_back(rows.shunt[static_cast<std::size_t>(node)]);
      b.push_back(rows.inflow[static_cast<std::size_t>(node)]);
      if (static_cast<std::int64_t>(node) == rows.inlet_node) b.back() += inlet_flow;
      if (v < 0) continue;  // the forest's roots: no vessel above
      out.vessels.push_back(v);
      out.resistance[static_cast<std::size_t>(v)] = vessel_resistance(net, blood, static_cast<std::size_t>(v));
    }
    conductance.assign(out.nodes.size(), 0.0);
    out.nodes_by_label = out.nodes;
    std::sort(out.nodes_by_label.begin(), out.nodes_by_label.end());
  });
  // A sweep's solve: the share's conductances 1 / R (as the one-process system takes them),
  // the distributed elimination, each vessel's flow from its nodes' pressures.
  auto solve = [&](const std::vector<double>& r, SteadyFlow& s) {
    for (std::size_t k = 0; k < out.nodes.size(); ++k) {
      const std::int32_t v = cut.parent_edge[static_cast<std::size_t>(out.nodes[k])];
      conductance[k] = v >= 0 ? 1 / r[static_cast<std::size_t>(v)] : 0.0;
    }
    x.assign(b.begin(), b.end());
    if (const std::int64_t floating = system->factorize_solve(conductance, shunt, x); floating >= 0) {
      refuse_floating_part_everywhere(net, floating);
    }
    // Whole-network arrays, sized once: a sweep touches this rank's entries alone (the others
    // stay 0), so that its work is its share's.
    if (s.node_pressure.size() != net.node_count()) s.node_pressure.assign(net.node_count(), 0.0);
    if (s.flow.size() != net.vessel_count()) s.flow.assign(net.vessel_count(), 0.0);
    for (std::size_t k = 0; k < out.nodes.size(); ++k) s.node_pressure[static_cast<std::size_t>(out.nodes[k])] = x[k];
    for (std::size_t k = 0; k < system->root_parents().size(); ++k)
      s.node_pressure[static_cast<std::size_t>(system->root_parents()[k])] = system->root_parent_potentials()[k];
    for (const std::int32_t vessel : out.vessels) {
      const auto v = static_cast<std::size_t>(vessel);
      s.flow[v] = (s.node_pressure[static_cast<std::size_t>(net.from[v])] - s.node_pressure[static_cast<std::size_t>(net.to[v])]) / r[v];
    }
    // The inlet's node may lie on a share (where the forest's root is another node).
    const bool holds_inlet = rows.inlet_node >= 0 && std::binary_search(out.nodes_by_label.begin(), out.nodes_by_label.end(),
                                                                       static_cast<std::int32_t>(rows.inlet_node));
    s.inlet_pressure = holds_inlet ? s.node_pressure[static_cast<std::size_t>(rows.inlet_node)]
                                   : std::numeric_limits<double>::quiet_NaN();
    ++out.sweeps;
  };
  auto largest = [](double x) {
    double mine = std::isnan(x) ? -std::numeric_limits<double>::infinity() : x, all = mine;
    MPI_Allreduce(&mine, &all, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    return all == -std::numeric_limits<double>::infinity() ? std::numeric_limits<double>::quiet_NaN() : all;
  };
  const DistendedPart part{out.vessels, out.nodes, solve, largest, [](const std::function<void()>& step) { on_every_rank(step); }};
  out.flow = iterate_distended(net, blood, laws, viscosity, part, out.resistance, threads);
  out.traffic = system->traffic();
  return out;
}

}  // namespace hemotree
