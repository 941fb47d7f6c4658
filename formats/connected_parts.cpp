#include "formats/connected_parts.hpp"

#include <algorithm>
#include <cstdio>
#include <utility>

#include "core/setting_error.hpp"

namespace hemotree {

namespace {

// A list of NodeBoundary values and the run's list, read alike.
struct NodeBoundaryList {
  std::span<const NodeBoundary> list;
  std::size_t size() const { return list.size(); }
  std::int32_t node(std::size_t i) const { return list[i].node; }
  BoundaryType type(std::size_t i) const { return list[i].type; }
  const Waveform& waveform(std::size_t i) const { return list[i].waveform; }
};

template <class Boundaries>
ConnectedParts parts_of(const Network& net, const Boundaries& boundaries) {
  const std::size_t nodes = net.node_count(), n = net.vessel_count();
  NodeParts roots(net);
  // Parts numbered as their roots are first met along the vessels, then sorted.
  std::vector<std::int32_t> part_of_root(nodes, -1);
  std::vector<ConnectedPart> parts;
  std::vector<std::int32_t> part_of_node(nodes, -1);
  for (std::size_t v = 0; v < n; ++v) {
    const auto r = static_cast<std::size_t>(roots.root(net.from[v]));
    if (part_of_root[r] < 0) {
      part_of_root[r] = static_cast<std::int32_t>(parts.size());
      parts.emplace_back().lowest_vessel_id = net.id[v];
    }
    ConnectedPart& part = parts[static_cast<std::size_t>(part_of_root[r])];
    ++part.vessels;
    part.lowest_vessel_id = std::min(part.lowest_vessel_id, net.id[v]);
    for (const std::int32_t i : {net.from[v], net.to[v]}) {
      auto& mine = part_of_node[static_cast<std::size_t>(i)];
      if (mine < 0) {
        mine = part_of_root[r];
        ++part.nodes;
      }
    }
  }
  for (std::size_t i = 0; i < boundaries.size(); ++i) {
    const std::int32_t node = boundaries.node(i), k = part_of_node[static_cast<std::size_t>(node)];
    if (k < 0) continue;
    ConnectedPart& part = parts[static_cast<std::size_t>(k)];
    part.boundary_nodes.push_back(node);
    if (boundaries.type(i) != BoundaryType::flow) {
      part.pressure_reference = true;
      continue;
    }
    const Waveform& wave = boundaries.waveform(i);
    const double q = wave.mean_value();
    part.net_inflow += q;
    part.largest_flow = std::max(part.largest_flow, std::abs(q));
    if (wave.shape != Waveform::Shape::constant) part.time_varying_flows = true;
  }

  std::vector<std::int32_t> order(parts.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::int32_t a, std::int32_t b) {
    const ConnectedPart &pa = parts[static_cast<std::size_t>(a)], &pb = parts[static_cast<std::size_t>(b)];
    return pa.vessels != pb.vessels ? pa.vessels > pb.vessels : pa.lowest_vessel_id < pb.lowest_vessel_id;
  });
  std::vector<std::int32_t> rank(parts.size());
  ConnectedParts out;
  out.parts.reserve(parts.size());
  for (std::size_t k = 0; k < order.size(); ++k) {
    rank[static_cast<std::size_t>(order[k])] = static_cast<std::int32_t>(k);
    out.parts.push_back(std::move(parts[static_cast<std::size_t>(order[k])]));
  }
  for (auto& k : part_of_node)
    if (k >= 0) k = rank[static_cast<std::size_t>(k)];
  for (ConnectedPart& part : out.parts) std::sort(part.boundary_nodes.begin(), part.boundary_nodes.end());
  out.part_of_node = std::move(part_of_node);
  return out;
}

}  // namespace

ConnectedParts connected_parts(const Network& net, std::span<const NodeBoundary> boundaries) {
  return parts_of(net, NodeBoundaryList{boundaries});
}

ConnectedParts connected_parts(const Network& net, const RunBoundaries& boundaries) { return parts_of(net, boundaries); }

ConnectedParts connected_parts(const Network& net) {
  const std::vector<NodeBoundary> boundaries = node_boundaries(net);
  return connected_parts(net, boundaries);
}

namespace {

std::string refusal_of(const Network& net, const ConnectedParts& parts) {
  std::vector<const ConnectedPart*> floating;
  for (const ConnectedPart& part : parts.parts)
    if (!part.pressure_reference) floating.push_back(&part);
  if (floating.empty()) return {};
  const std::size_t total = parts.parts.size();
  std::string why;
  for (const ConnectedPart* part : floating) {
    why += why.empty() ? "" : "; ";
    why += part_name(*part);
    if (part->boundary_nodes.empty())
      why += " has no boundary condition: it is cut off from every inflow and outflow";
    else
      why += " has flow boundaries only: its pressure is undetermined (at " +
             std::string(part->boundary_nodes.size() == 1 ? "node " : "nodes ") + boundary_node_list(net, *part) +
             "; " + flow_balance(*part) + ")";
  }
  const std::string which = total == 1 ? "the network has no pressure to refer to"
                            : floating.size() == total
                                ? "none of the network's " + std::to_string(total) + " connected parts has a pressure to refer to"
                            : floating.size() == 1
                                ? "1 of the network's " + std::to_string(total) + " connected parts has no pressure to refer to"
                                : std::to_string(floating.size()) + " of the network's " + std::to_string(total) +
                                      " connected parts have no pressure to refer to";
  const std::string pressure_at = "hemosolve " + placeholder("pressure_at") + " NODE=PRESSURE";
  const std::string remedy = floating.size() == 1 ? " (give a node a pressure or an outlet; where the flows balance, " +
                                                        pressure_at + " fixes the level): "
                                                  : " (give a node of each a pressure or an outlet; where a part's flows "
                                                    "balance, " + pressure_at + " fixes its level): ";
  return which + remedy + why;
}

}  // namespace

std::string pressure_reference_refusal(const Network& net, std::span<const NodeBoundary> boundaries) {
  return refusal_of(net, connected_parts(net, boundaries));
}

std::string pressure_reference_refusal(const Network& net, const RunBoundaries& boundaries) {
  return refusal_of(net, connected_parts(net, boundaries));
}

std::string part_name(const ConnectedPart& part) {
  return "the part with vessel " + std::to_string(part.lowest_vessel_id) + " (" + std::to_string(part.vessels) +
         (part.vessels == 1 ? " vessel)" : " vessels)");
}

std::string boundary_node_list(const Network& net, const ConnectedPart& part, std::size_t shown) {
  const std::size_t count = part.boundary_nodes.size();
  std::string s;
  for (std::size_t k = 0; k < std::min(count, shown); ++k)
    s += (k == 0 ? "" : ", ") + std::to_string(net.node_id[static_cast<std::size_t>(part.boundary_nodes[k])]);
  if (count > shown) s += " and " + std::to_string(count - shown) + " more";
  return s;
}

std::string flow_balance(const ConnectedPart& part) {
  const std::string mean = part.time_varying_flows ? "mean " : "";
  if (part.flows_balance()) return "the " + mean + "flows balance";
  char text[64];
  std::snprintf(text, sizeof text, "%.6g ml/min", part.net_inflow * 60e6);
  return "the net " + mean + "inflow is " + text;
}

}  // namespace hemotree
