#include "network_flow/flow_network.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace hemotree {

FlowNetwork::FlowNetwork(std::size_t nodes, std::span<const std::int32_t> a, std::span<const std::int32_t> b,
                         std::span<const unsigned char> prescribed)
    : nodes_(nodes), a_(a.begin(), a.end()), b_(b.begin(), b.end()) {
  if (a.size() != b.size() || prescribed.size() != nodes)
    throw std::invalid_argument("FlowNetwork: " + std::to_string(a.size()) + " edge starts, " +
                                std::to_string(b.size()) + " ends, " + std::to_string(prescribed.size()) +
                                " prescribed flags for " + std::to_string(nodes) + " nodes");
  auto check_edge = [&](std::size_t e) {
    const auto i = static_cast<std::size_t>(a_[e]), j = static_cast<std::size_t>(b_[e]);
    if (i >= nodes || j >= nodes || i == j)
      throw std::invalid_argument("FlowNetwork: edge " + std::to_string(e) + " joins nodes " + std::to_string(i) +
                                  " and " + std::to_string(j) + " of " + std::to_string(nodes));
  };
  all_free_ = std::none_of(prescribed.begin(), prescribed.end(), [](unsigned char p) { return p != 0; });
  if (all_free_) {
    for (std::size_t e = 0; e < a_.size(); ++e) check_edge(e);
    system_ = NodalSystem(nodes, a_, b_);
    return;
  }
  free_index_.assign(nodes, -1);
  for (std::size_t i = 0; i < nodes; ++i)
    if (!prescribed[i]) {
      free_index_[i] = static_cast<std::int32_t>(free_node_.size());
      free_node_.push_back(static_cast<std::int32_t>(i));
    }
  std::vector<std::int32_t> inner_a, inner_b;
  for (std::size_t e = 0; e < a_.size(); ++e) {
    check_edge(e);
    const auto i = static_cast<std::size_t>(a_[e]), j = static_cast<std::size_t>(b_[e]);
    const bool free_i = free_index_[i] >= 0, free_j = free_index_[j] >= 0;
    if (free_i && free_j) {
      inner_edge_.push_back(static_cast<std::int32_t>(e));
      inner_a.push_back(free_index_[i]);
      inner_b.push_back(free_index_[j]);
    } else if (free_i || free_j) {
      boundary_edge_.push_back(static_cast<std::int32_t>(e));
    }
  }
  system_ = NodalSystem(free_node_.size(), std::move(inner_a), std::move(inner_b));
  inner_conductance_.resize(inner_edge_.size());
  free_shunt_.resize(free_node_.size());
  rhs_.resize(free_node_.size());
}

std::int64_t FlowNetwork::factorize(std::span<const double> conductance, std::span<const double> shunt) {
  if (conductance.size() != a_.size() || shunt.size() != nodes_)
    throw std::invalid_argument("FlowNetwork::factorize: " + std::to_string(conductance.size()) +
                                " conductances and " + std::to_string(shunt.size()) + " shunts for " +
                                std::to_string(a_.size()) + " edges and " + std::to_string(nodes_) + " nodes");
  conductance_.assign(conductance.begin(), conductance.end());
  if (all_free_) return system_.factorize(conductance, shunt);
  for (std::size_t k = 0; k < inner_edge_.size(); ++k) inner_conductance_[k] = conductance[static_cast<std::size_t>(inner_edge_[k])];
  for (std::size_t r = 0; r < free_node_.size(); ++r) free_shunt_[r] = shunt[static_cast<std::size_t>(free_node_[r])];
  for (const std::int32_t e : boundary_edge_) {
    const std::int32_t i = free_index_[static_cast<std::size_t>(a_[static_cast<std::size_t>(e)])];
    const std::int32_t r = i >= 0 ? i : free_index_[static_cast<std::size_t>(b_[static_cast<std::size_t>(e)])];
    free_shunt_[static_cast<std::size_t>(r)] += conductance[static_cast<std::size_t>(e)];
  }
  const std::int64_t floating = system_.factorize(inner_conductance_, free_shunt_);
  return floating < 0 ? -1 : free_node_[static_cast<std::size_t>(floating)];
}

void FlowNetwork::solve(std::span<const double> inflow, std::span<double> pressure) const {
  if (inflow.size() != nodes_ || pressure.size() != nodes_)
    throw std::invalid_argument("FlowNetwork::solve: vectors of " + std::to_string(inflow.size()) + " and " +
                                std::to_string(pressure.size()) + " for " + std::to_string(nodes_) + " nodes");
  if (all_free_) {
    system_.solve(inflow, pressure);
    return;
  }
  for (std::size_t r = 0; r < free_node_.size(); ++r) rhs_[r] = inflow[static_cast<std::size_t>(free_node_[r])];
  for (const std::int32_t e : boundary_edge_) {
    const auto i = static_cast<std::size_t>(a_[static_cast<std::size_t>(e)]);
    const auto j = static_cast<std::size_t>(b_[static_cast<std::size_t>(e)]);
    const bool i_free = free_index_[i] >= 0;
    const std::size_t row = static_cast<std::size_t>(free_index_[i_free ? i : j]);
    rhs_[row] += conductance_[static_cast<std::size_t>(e)] * pressure[i_free ? j : i];
  }
  system_.solve(rhs_, rhs_);
  for (std::size_t r = 0; r < free_node_.size(); ++r) pressure[static_cast<std::size_t>(free_node_[r])] = rhs_[r];
}

void FlowNetwork::edge_flows(std::span<const double> pressure, std::span<double> flow) const {
  for (std::size_t e = 0; e < a_.size(); ++e)
    flow[e] = conductance_[e] * (pressure[static_cast<std::size_t>(a_[e])] - pressure[static_cast<std::size_t>(b_[e])]);
}

}  // namespace hemotree
