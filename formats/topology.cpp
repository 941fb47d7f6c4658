#include "formats/topology.hpp"

#include <string>
#include <utility>

#include <boost/graph/breadth_first_search.hpp>

#include "cli/errors.hpp"

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

std::vector<std::int32_t> generations_from_inlets(const Network& net) {
  const NetworkGraph g = make_graph(net);
  std::vector<std::int32_t> in_degree(net.node_count(), 0);
  for (std::size_t v = 0; v < net.vessel_count(); ++v) ++in_degree[net.to[v]];

  // Generation of the vessel entering each node; -1 at inlet nodes.
  std::vector<std::int32_t> node_generation(net.node_count(), -1);
  std::vector<std::int32_t> generation(net.vessel_count(), -1);
  std::vector<boost::default_color_type> colour(net.node_count(), boost::white_color);
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
  const auto generation = generations_from_inlets(net);
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
  std::vector<std::int32_t> order{static_cast<std::int32_t>(root)};
  order.reserve(children.offset.size() - 1);
  for (std::size_t head = 0; head < order.size(); ++head) {
    const auto v = static_cast<std::size_t>(order[head]);
    for (auto k = children.offset[v]; k < children.offset[v + 1]; ++k)
      order.push_back(children.index[k]);
  }
  return order;
}

}  // namespace hemotree
