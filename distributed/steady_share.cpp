#include "distributed/steady_share.hpp"

#include <algorithm>
#include <limits>

#include <mpi.h>

#include "distributed/network_cut.hpp"

namespace hemotree {

SteadyShare::SteadyShare(const Network& net, const TreeCut& cut, const std::function<Row(std::int32_t node)>& row)
    : net_(net), cut_(cut), system_(MPI_COMM_WORLD, cut) {
  for (const std::int32_t node : system_.nodes()) {
    const Row r = row(node);
    shunt_.push_back(r.shunt);
    inflow_.push_back(r.inflow);
    if (const std::int32_t v = cut.parent_edge[static_cast<std::size_t>(node)]; v >= 0) vessels_.push_back(v);  // the forest's roots have none
  }
  conductance_.assign(shunt_.size(), 0.0);
  sorted_nodes_.assign(system_.nodes().begin(), system_.nodes().end());
  std::sort(sorted_nodes_.begin(), sorted_nodes_.end());
}

SteadyShare::SteadyShare(const Network& net, const TreeCut& cut, const SteadyRows& rows, double inlet_flow)
    : SteadyShare(net, cut, [&](std::int32_t node) {
        const auto i = static_cast<std::size_t>(node);
        Row r{rows.shunt[i], rows.inflow[i]};
        if (static_cast<std::int64_t>(node) == rows.inlet_node) r.inflow += inlet_flow;
        return r;
      }) {
  inlet_node_ = rows.inlet_node;
}

bool SteadyShare::holds(std::int32_t node) const {
  return std::binary_search(sorted_nodes_.begin(), sorted_nodes_.end(), node);
}

std::span<const double> SteadyShare::solve_nodes(std::span<const double> conductance) {
  x_.assign(inflow_.begin(), inflow_.end());
  if (const std::int64_t floating = system_.factorize_solve(conductance, shunt_, x_); floating >= 0)
    refuse_floating_part_everywhere(net_, floating);
  return x_;
}

void SteadyShare::solve(const std::vector<double>& resistance, SteadyFlow& s) {
  const std::span<const std::int32_t> nodes = system_.nodes();
  // Each node's conductance to its parent, 1 / R as the one-process system takes it.
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    const std::int32_t v = cut_.parent_edge[static_cast<std::size_t>(nodes[k])];
    conductance_[k] = v >= 0 ? 1 / resistance[static_cast<std::size_t>(v)] : 0.0;
  }
  solve_nodes(conductance_);
  // Whole-network arrays, sized once: a solve writes this rank's entries alone, so that its
  // work is its share's.
  if (s.node_pressure.size() != net_.node_count()) s.node_pressure.assign(net_.node_count(), 0.0);
  if (s.flow.size() != net_.vessel_count()) s.flow.assign(net_.vessel_count(), 0.0);
  for (std::size_t k = 0; k < nodes.size(); ++k) s.node_pressure[static_cast<std::size_t>(nodes[k])] = x_[k];
  for (std::size_t k = 0; k < system_.root_parents().size(); ++k)
    s.node_pressure[static_cast<std::size_t>(system_.root_parents()[k])] = system_.root_parent_potentials()[k];
  for (const std::int32_t vessel : vessels_) {
    const auto v = static_cast<std::size_t>(vessel);
    s.flow[v] = (s.node_pressure[static_cast<std::size_t>(net_.from[v])] -
                 s.node_pressure[static_cast<std::size_t>(net_.to[v])]) /
                resistance[v];
  }
  // The inlet's node may lie on a share (where the forest's root is another node).
  s.inlet_pressure = inlet_node_ >= 0 && holds(static_cast<std::int32_t>(inlet_node_))
                         ? s.node_pressure[static_cast<std::size_t>(inlet_node_)]
                         : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace hemotree
