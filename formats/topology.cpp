#include "formats/topology.hpp"

#include <algorithm>
#include <string>
#include <utility>

#include <boost/graph/breadth_first_search.hpp>

#include "core/errors.hpp"

namespace hemotree {

NetworkGraph make_graph(const Network& net) {
  std::vector<std::pair<std::int32_t, std::int32_t>> edges(net.vessel_count());
  std::vector<VesselEdge> bundles(net.vessel_count());
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    edges[v] = {net.from[v], net.to[v]};
    bundles[v].vessel = static_cast<std::int32_t>(v);
  }
  return NetworkGraph(boost::edges_are_unsorted_multi_pass, edges.begin(), edges.end(),
                      bundles.begin(), net.node_count());
}

namespace {

// What no directed path from an inlet node reaches (a measured network's vessels written
// against the flow, a closed loop): breadth first over the undirected graph, from every node
// reached so far, then from the lowest node of each part still unreached. A vessel's
// generation is its nearer end's + 1, so every vessel has one, and a tree's are unchanged.
void reach_the_rest(const Network& net, std::vector<boost::default_color_type>& colour,
                    std::vector<std::int32_t>& node_generation, std::vector<std::int32_t>& generation) {
  const std::size_t nodes = net.node_count(), n = net.vessel_count();
  if (std::find(generation.begin(), generation.end(), -1) == generation.end()) return;
  std::vector<std::int64_t> offset(nodes + 1, 0);
  for (std::size_t v = 0; v < n; ++v) {
    ++offset[static_cast<std::size_t>(net.from[v]) + 1];
    ++offset[static_cast<std::size_t>(net.to[v]) + 1];
  }
  for (std::size_t i = 0; i < nodes; ++i) offset[i + 1] += offset[i];
  std::vector<std::int32_t> incident(static_cast<std::size_t>(offset[nodes]));
  std::vector<std::int64_t> fill(offset.begin(), offset.end() - 1);
  for (std::size_t v = 0; v < n; ++v) {
    incident[static_cast<std::size_t>(fill[static_cast<std::size_t>(net.from[v])]++)] = static_cast<std::int32_t>(v);
    incident[static_cast<std::size_t>(fill[static_cast<std::size_t>(net.to[v])]++)] = static_cast<std::int32_t>(v);
  }
  std::vector<std::int32_t> queue;
  for (std::size_t i = 0; i < nodes; ++i)
    if (colour[i] != boost::white_color) queue.push_back(static_cast<std::int32_t>(i));
  auto sweep = [&] {
    for (std::size_t head = 0; head < queue.size(); ++head) {
      const auto i = static_cast<std::size_t>(queue[head]);
      for (auto k = offset[i]; k < offset[i + 1]; ++k) {
        const auto v = static_cast<std::size_t>(incident[static_cast<std::size_t>(k)]);
        if (generation[v] < 0) generation[v] = node_generation[i] + 1;
        const auto other = static_cast<std::size_t>(net.from[v]) == i ? static_cast<std::size_t>(net.to[v])
                                                                       : static_cast<std::size_t>(net.from[v]);
        if (colour[other] == boost::white_color) {
          colour[other] = boost::black_color;
          node_generation[other] = node_generation[i] + 1;
          queue.push_back(static_cast<std::int32_t>(other));
        }
      }
    }
    queue.clear();
  };
  sweep();
  for (std::size_t v = 0; v < n; ++v) {
    if (generation[v] >= 0) continue;
    const auto root = static_cast<std::size_t>(std::min(net.from[v], net.to[v]));
    colour[root] = boost::black_color;
    node_generation[root] = -1;
    queue.push_back(static_cast<std::int32_t>(root));
    sweep();
  }
}

// Generations along the vessels' direction from the nodes no vessel enters; -1 for vessels
// no such path reaches. colour and node_generation: per node, reached or not, and the
// generation of the vessel that reached it (-1 at inlet nodes).
std::vector<std::int32_t> directed_generations(const Network& net, std::vector<boost::default_color_type>& colour,
                                               std::vector<std::int32_t>& node_generation) {
  const NetworkGraph g = make_graph(net);
  std::vector<std::int32_t> in_degree(net.node_count(), 0);
  for (std::size_t v = 0; v < net.vessel_count(); ++v) ++in_degree[net.to[v]];

  node_generation.assign(net.node_count(), -1);
  std::vector<std::int32_t> generation(net.vessel_count(), -1);
  colour.assign(net.node_count(), boost::white_color);
  auto colours = boost::make_iterator_property_map(colour.begin(), get(boost::vertex_index, g));

  struct Visitor : boost::default_bfs_visitor {
    std::vector<std::int32_t>* node_generation;
    std::vector<std::int32_t>* generation;
    void tree_edge(NetworkGraph::edge_descriptor e, const NetworkGraph& graph) const {
      const std::int32_t v = graph[e].vessel;
      const std::int32_t g = (*node_generation)[source(e, graph)] + 1;
      (*generation)[v] = g;
      (*node_generation)[target(e, graph)] = g;
    }
  } visitor;
  visitor.node_generation = &node_generation;
  visitor.generation = &generation;

  for (std::size_t n = 0; n < net.node_count(); ++n)
    if (in_degree[n] == 0 && colour[n] == boost::white_color)
      boost::breadth_first_visit(g, static_cast<std::int32_t>(n),
                                 boost::visitor(visitor).color_map(colours));
  // Vessels that are not tree edges (joining an already reached node) take their
  // feeding vessel's generation + 1 as well.
  for (std::size_t v = 0; v < net.vessel_count(); ++v)
    if (generation[v] < 0 && colour[net.from[v]] != boost::white_color)
      generation[v] = node_generation[net.from[v]] + 1;
  return generation;
}

}  // namespace

std::vector<std::int32_t> generations_from_inlets(const Network& net) {
  std::vector<boost::default_color_type> colour;
  std::vector<std::int32_t> node_generation;
  std::vector<std::int32_t> generation = directed_generations(net, colour, node_generation);
  reach_the_rest(net, colour, node_generation, generation);
  return generation;
}

std::size_t check_rooted_tree(const Network& net) {
  auto name = [&](std::size_t v) { return "vessel " + std::to_string(net.id[v]); };
  if (net.vessel_count() == 0) throw InputError("the network has no vessels");
  std::vector<std::int32_t> entering(net.node_count(), -1);
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    if (entering[net.to[v]] >= 0)
      throw InputError("not a tree: " + name(v) + " and " +
                       name(static_cast<std::size_t>(entering[net.to[v]])) +
                       " both end at node " + std::to_string(net.node_id[net.to[v]]));
    entering[net.to[v]] = static_cast<std::int32_t>(v);
  }
  std::int64_t root = -1;
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    if (entering[net.from[v]] >= 0) continue;
    if (root >= 0)
      throw InputError("not a tree: several roots, " + name(static_cast<std::size_t>(root)) +
                       " and " + name(v) + " are both fed by no vessel");
    root = static_cast<std::int64_t>(v);
  }
  if (root < 0) throw InputError("not a tree: every vessel is fed by another (a closed loop)");
  std::vector<boost::default_color_type> colour;
  std::vector<std::int32_t> node_generation;
  const auto generation = directed_generations(net, colour, node_generation);
  for (std::size_t v = 0; v < net.vessel_count(); ++v)
    if (generation[v] < 0)
      throw InputError("not a tree: " + name(v) +
                       " is not reached from the root (its 'from' node lies on a loop)");
  return static_cast<std::size_t>(root);
}

Children children_of(const Network& net) {
  std::vector<std::int32_t> leaving_count(net.node_count() + 1, 0);
  for (std::size_t v = 0; v < net.vessel_count(); ++v) ++leaving_count[net.from[v] + 1];
  std::vector<std::int64_t> node_offset(net.node_count() + 1, 0);
  for (std::size_t n = 0; n < net.node_count(); ++n)
    node_offset[n + 1] = node_offset[n] + leaving_count[n + 1];
  std::vector<std::int32_t> leaving(net.vessel_count());
  std::vector<std::int64_t> fill(node_offset.begin(), node_offset.end() - 1);
  for (std::size_t v = 0; v < net.vessel_count(); ++v)
    leaving[fill[net.from[v]]++] = static_cast<std::int32_t>(v);

  Children c;
  c.offset.resize(net.vessel_count() + 1);
  c.index.reserve(net.vessel_count());
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    c.offset[v] = static_cast<std::int64_t>(c.index.size());
    const std::int32_t n = net.to[v];
    for (std::int64_t k = node_offset[n]; k < node_offset[n + 1]; ++k) c.index.push_back(leaving[k]);
  }
  c.offset[net.vessel_count()] = static_cast<std::int64_t>(c.index.size());
  return c;
}

std::vector<std::int32_t> breadth_first_order(const Children& children, std::size_t root) {
  const std::int32_t roots[] = {static_cast<std::int32_t>(root)};
  return breadth_first_order(children, roots);
}

std::vector<std::int32_t> inlet_vessels(const Network& net) {
  std::vector<std::uint8_t> entered(net.node_count(), 0);
  for (std::size_t v = 0; v < net.vessel_count(); ++v) entered[static_cast<std::size_t>(net.to[v])] = 1;
  std::vector<std::int32_t> roots;
  for (std::size_t v = 0; v < net.vessel_count(); ++v)
    if (!entered[static_cast<std::size_t>(net.from[v])]) roots.push_back(static_cast<std::int32_t>(v));
  return roots;
}

std::vector<std::int32_t> breadth_first_order(const Children& children, std::span<const std::int32_t> roots) {
  std::vector<std::int32_t> order(roots.begin(), roots.end());
  order.reserve(children.offset.size() - 1);
  for (std::size_t head = 0; head < order.size(); ++head) {
    const auto v = static_cast<std::size_t>(order[head]);
    for (auto k = children.offset[v]; k < children.offset[v + 1]; ++k)
      order.push_back(children.index[k]);
  }
  return order;
}

}  // namespace hemotree
