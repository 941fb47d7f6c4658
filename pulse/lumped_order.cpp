#include "pulse/lumped_order.hpp"

#include <numeric>

#include "network_flow/nodal_system.hpp"

namespace hemotree {

LumpedOrder network_lumped_order(const Network& net, const std::vector<bool>& zero_d) {
  LumpedOrder order;
  std::vector<unsigned char> seen(net.node_count(), 0);
  auto visit = [&](std::int32_t node) {
    if (seen[static_cast<std::size_t>(node)]) return;
    seen[static_cast<std::size_t>(node)] = 1;
    order.nodes.push_back(node);
  };
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    if (!zero_d[v]) continue;
    order.vessels.push_back(static_cast<std::int32_t>(v));
    visit(net.from[v]);
    visit(net.to[v]);
  }
  return order;
}

LumpedOrder subtree_lumped_order(const Network& net, const std::vector<bool>& zero_d) {
  LumpedOrder given = network_lumped_order(net, zero_d);
  const std::size_t nodes = given.nodes.size(), edges = given.vessels.size();
  // Each node's place in the given order, and its vessels by their places (increasing).
  std::vector<std::int32_t> place(net.node_count(), -1);
  for (std::size_t k = 0; k < nodes; ++k) place[static_cast<std::size_t>(given.nodes[k])] = static_cast<std::int32_t>(k);
  std::vector<std::int32_t> a(edges), b(edges);
  for (std::size_t e = 0; e < edges; ++e) {
    const auto v = static_cast<std::size_t>(given.vessels[e]);
    a[e] = place[static_cast<std::size_t>(net.from[v])];
    b[e] = place[static_cast<std::size_t>(net.to[v])];
  }
  // A forest? (union-find, roots kept lowest; a loop or a doubled vessel says no)
  std::vector<std::int32_t> root(nodes);
  std::iota(root.begin(), root.end(), 0);
  auto find = [&](std::int32_t k) {
    while (root[static_cast<std::size_t>(k)] != k) k = root[static_cast<std::size_t>(k)] = root[static_cast<std::size_t>(root[static_cast<std::size_t>(k)])];
    return k;
  };
  for (std::size_t e = 0; e < edges; ++e) {
    const std::int32_t ra = find(a[e]), rb = find(b[e]);
    if (ra == rb) return given;
    root[static_cast<std::size_t>(std::max(ra, rb))] = std::min(ra, rb);
  }
  std::vector<std::int32_t> offset(nodes + 1, 0), incident(2 * edges);
  for (std::size_t e = 0; e < edges; ++e) {
    ++offset[static_cast<std::size_t>(a[e]) + 1];
    ++offset[static_cast<std::size_t>(b[e]) + 1];
  }
  std::partial_sum(offset.begin(), offset.end(), offset.begin());
  std::vector<std::int32_t> fill(offset.begin(), offset.end() - 1);
  for (std::size_t e = 0; e < edges; ++e) {
    incident[static_cast<std::size_t>(fill[static_cast<std::size_t>(a[e])]++)] = static_cast<std::int32_t>(e);
    incident[static_cast<std::size_t>(fill[static_cast<std::size_t>(b[e])]++)] = static_cast<std::int32_t>(e);
  }
  // Each tree rooted at its lowest node: preorder (parents first), each node's parent vessel.
  std::vector<std::int32_t> preorder, via(nodes, -1), parent(nodes, -1);
  preorder.reserve(nodes);
  std::vector<unsigned char> seen(nodes, 0);
  std::vector<std::int32_t> stack;
  for (std::size_t first = 0; first < nodes; ++first) {
    if (seen[first]) continue;
    seen[first] = 1;
    stack.push_back(static_cast<std::int32_t>(first));
    while (!stack.empty()) {
      const auto k = static_cast<std::size_t>(stack.back());
      stack.pop_back();
      preorder.push_back(static_cast<std::int32_t>(k));
      for (auto j = offset[k]; j < offset[k + 1]; ++j) {
        const auto e = static_cast<std::size_t>(incident[static_cast<std::size_t>(j)]);
        const auto child = static_cast<std::size_t>(a[e] == static_cast<std::int32_t>(k) ? b[e] : a[e]);
        if (seen[child]) continue;
        seen[child] = 1;
        parent[child] = static_cast<std::int32_t>(k);
        via[child] = static_cast<std::int32_t>(e);
        stack.push_back(static_cast<std::int32_t>(child));
      }
    }
  }
  // The sweeps' tasks (network_flow/nodal_system: the largest subtrees within its limit) and
  // the nodes above them.
  const std::size_t limit = NodalSystem::task_size_limit(nodes);
  if (limit == 0) return given;
  std::vector<std::int32_t> size(nodes, 1), task(nodes, -1);
  for (std::size_t i = nodes; i-- > 0;) {
    const auto k = static_cast<std::size_t>(preorder[i]);
    if (parent[k] >= 0) size[static_cast<std::size_t>(parent[k])] += size[k];
  }
  std::int32_t tasks = 0;
  for (const std::int32_t node : preorder) {
    const auto k = static_cast<std::size_t>(node);
    if (static_cast<std::size_t>(size[k]) > limit) continue;
    task[k] = parent[k] >= 0 && task[static_cast<std::size_t>(parent[k])] >= 0 ? task[static_cast<std::size_t>(parent[k])] : tasks++;
  }
  // Each task's nodes in the given order, the task where its root was: siblings, top nodes
  // and every node's vessels keep their given order.
  std::vector<std::int32_t> task_offset(static_cast<std::size_t>(tasks) + 1, 0), task_nodes;
  for (std::size_t k = 0; k < nodes; ++k)
    if (task[k] >= 0) ++task_offset[static_cast<std::size_t>(task[k]) + 1];
  std::partial_sum(task_offset.begin(), task_offset.end(), task_offset.begin());
  task_nodes.resize(static_cast<std::size_t>(task_offset.back()));
  std::vector<std::int32_t> cursor(task_offset.begin(), task_offset.end() - 1);
  for (std::size_t k = 0; k < nodes; ++k)
    if (task[k] >= 0) task_nodes[static_cast<std::size_t>(cursor[static_cast<std::size_t>(task[k])]++)] = static_cast<std::int32_t>(k);
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

}  // namespace hemotree
