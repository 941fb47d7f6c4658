#include "pulse/lumped_order.hpp"

#include <numeric>

#include "formats/run_boundaries.hpp"
#include "network_flow/nodal_system.hpp"

namespace hemotree {

std::vector<std::int32_t> nodes_by_first_appearance(std::span<const std::int32_t> vessels,
                                                    std::span<const std::int32_t> from,
                                                    std::span<const std::int32_t> to, std::size_t nodes) {
  std::vector<std::int32_t> order;
  std::vector<unsigned char> seen(nodes, 0);
  for (const std::int32_t v : vessels)
    for (const std::int32_t k : {from[static_cast<std::size_t>(v)], to[static_cast<std::size_t>(v)]})
      if (!seen[static_cast<std::size_t>(k)]) {
        seen[static_cast<std::size_t>(k)] = 1;
        order.push_back(k);
      }
  return order;
}

LumpedOrder network_lumped_order(const Network& net, const std::vector<bool>& zero_d) {
  LumpedOrder order;
  for (std::size_t v = 0; v < net.vessel_count(); ++v)
    if (zero_d[v]) order.vessels.push_back(static_cast<std::int32_t>(v));
  const std::vector<std::int32_t> nodes = nodes_by_first_appearance(order.vessels, net.from, net.to, net.node_count());
  order.nodes.assign(nodes.begin(), nodes.end());
  return order;
}

LumpedOrder subtree_lumped_order(const Network& net, const std::vector<bool>& zero_d) {
  LumpedOrder given = network_lumped_order(net, zero_d);
  const std::size_t nodes = given.nodes.size(), edges = given.vessels.size();
  if (NodalSystem::task_size_limit(nodes) == 0) return given;
  // The vessels' ends by the nodes' places in the given order, and each node's vessels by
  // their places (increasing).
  std::vector<std::int32_t> place(net.node_count(), -1);
  for (std::size_t k = 0; k < nodes; ++k) place[static_cast<std::size_t>(given.nodes[k])] = static_cast<std::int32_t>(k);
  std::vector<std::int32_t> a(edges), b(edges), offset(nodes + 1, 0), incident(2 * edges);
  for (std::size_t e = 0; e < edges; ++e) {
    const auto v = static_cast<std::size_t>(given.vessels[e]);
    a[e] = place[static_cast<std::size_t>(net.from[v])];
    b[e] = place[static_cast<std::size_t>(net.to[v])];
    ++offset[static_cast<std::size_t>(a[e]) + 1];
    ++offset[static_cast<std::size_t>(b[e]) + 1];
  }
  std::partial_sum(offset.begin(), offset.end(), offset.begin());
  std::vector<std::int32_t> fill(offset.begin(), offset.end() - 1);
  for (std::size_t e = 0; e < edges; ++e) {
    incident[static_cast<std::size_t>(fill[static_cast<std::size_t>(a[e])]++)] = static_cast<std::int32_t>(e);
    incident[static_cast<std::size_t>(fill[static_cast<std::size_t>(b[e])]++)] = static_cast<std::int32_t>(e);
  }
  // Each tree rooted at its lowest node, searched from there (parents before children): each
  // node's parent and the vessel from it. A node met again by another vessel closes a loop.
  std::vector<std::int32_t> reached, via(nodes, -1), parent(nodes, -1);
  reached.reserve(nodes);
  std::vector<unsigned char> seen(nodes, 0);
  for (std::size_t first = 0; first < nodes; ++first) {
    if (seen[first]) continue;
    seen[first] = 1;
    reached.push_back(static_cast<std::int32_t>(first));
    for (std::size_t next = reached.size() - 1; next < reached.size(); ++next) {
      const auto k = static_cast<std::size_t>(reached[next]);
      for (auto j = offset[k]; j < offset[k + 1]; ++j) {
        const std::int32_t e = incident[static_cast<std::size_t>(j)];
        if (e == via[k]) continue;
        const auto child = static_cast<std::size_t>(a[static_cast<std::size_t>(e)] == static_cast<std::int32_t>(k)
                                                        ? b[static_cast<std::size_t>(e)]
                                                        : a[static_cast<std::size_t>(e)]);
        if (seen[child]) return given;
        seen[child] = 1;
        parent[child] = static_cast<std::int32_t>(k);
        via[child] = e;
        reached.push_back(static_cast<std::int32_t>(child));
      }
    }
  }
  // The sweeps' tasks (network_flow/nodal_system), each one's nodes in the given order.
  const std::vector<std::int32_t> task = NodalSystem::subtree_tasks(parent, reached);
  std::vector<std::int32_t> task_offset(1, 0);
  for (const std::int32_t t : task)
    if (t >= 0) {
      if (static_cast<std::size_t>(t) + 2 > task_offset.size()) task_offset.resize(static_cast<std::size_t>(t) + 2, 0);
      ++task_offset[static_cast<std::size_t>(t) + 1];
    }
  std::partial_sum(task_offset.begin(), task_offset.end(), task_offset.begin());
  std::vector<std::int32_t> task_nodes(static_cast<std::size_t>(task_offset.back()));
  std::vector<std::int32_t> cursor(task_offset.begin(), task_offset.end() - 1);
  for (std::size_t k = 0; k < nodes; ++k)
    if (task[k] >= 0) task_nodes[static_cast<std::size_t>(cursor[static_cast<std::size_t>(task[k])]++)] = static_cast<std::int32_t>(k);
  // The nodes above the tasks where they were, each task where its root was.
  LumpedOrder order;
  order.nodes.reserve(nodes);
  order.vessels.reserve(edges);
  auto emit = [&](std::size_t k) {
    order.nodes.push_back(given.nodes[k]);
    if (via[k] >= 0) order.vessels.push_back(given.vessels[static_cast<std::size_t>(via[k])]);
  };
  for (std::size_t k = 0; k < nodes; ++k) {
    if (task[k] < 0) {
      emit(k);
    } else if (parent[k] < 0 || task[static_cast<std::size_t>(parent[k])] != task[k]) {
      const auto t = static_cast<std::size_t>(task[k]);
      for (auto j = task_offset[t]; j < task_offset[t + 1]; ++j) emit(static_cast<std::size_t>(task_nodes[static_cast<std::size_t>(j)]));
    }
  }
  return order;
}

LumpedOrder restrict_order(const LumpedOrder& order, const Network& net, const std::vector<bool>& keep) {
  LumpedOrder out;
  std::vector<unsigned char> end(net.node_count(), 0);
  for (const std::int32_t v : order.vessels) {
    if (!keep[static_cast<std::size_t>(v)]) continue;
    out.vessels.push_back(v);
    end[static_cast<std::size_t>(net.from[static_cast<std::size_t>(v)])] = 1;
    end[static_cast<std::size_t>(net.to[static_cast<std::size_t>(v)])] = 1;
  }
  for (const std::int32_t node : order.nodes)
    if (end[static_cast<std::size_t>(node)]) out.nodes.push_back(node);
  return out;
}

LumpedPlaces lumped_places(const Network& net, const std::vector<bool>& zero_d) {
  const LumpedOrder order = network_lumped_order(net, zero_d);
  LumpedPlaces p;
  p.node.assign(net.node_count(), -1);
  p.vessel.assign(net.vessel_count(), -1);
  for (std::size_t k = 0; k < order.nodes.size(); ++k) p.node[static_cast<std::size_t>(order.nodes[k])] = static_cast<std::int32_t>(k);
  for (std::size_t k = 0; k < order.vessels.size(); ++k) p.vessel[static_cast<std::size_t>(order.vessels[k])] = static_cast<std::int32_t>(k);
  // LumpedVessels::add_boundary_rows' capacitors: an RCR outlet with a capacitance at a 0D
  // vessel's node, in the run's list's order.
  const RunBoundaries boundaries(net);
  std::int32_t capacitors = 0;
  for (std::size_t i = 0; i < boundaries.size(); ++i) {
    if (!boundaries.is_outlet(i)) continue;
    const Outlet& o = boundaries.outlet(i);
    const bool capacitor = p.node[static_cast<std::size_t>(boundaries.node(i))] >= 0 && o.type == BoundaryType::rcr && o.c > 0;
    p.capacitor.push_back(capacitor ? static_cast<std::int32_t>(order.nodes.size()) + capacitors : -1);
    p.r1_edge.push_back(capacitor ? static_cast<std::int32_t>(order.vessels.size()) + capacitors : -1);
    capacitors += capacitor ? 1 : 0;
  }
  p.nodes = order.nodes.size() + static_cast<std::size_t>(capacitors);
  p.edges = order.vessels.size() + static_cast<std::size_t>(capacitors);
  return p;
}

}  // namespace hemotree
