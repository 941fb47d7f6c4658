// The network as a directed graph (nodes = vertices, vessels = edges from -> to), built
// with Boost.Graph's compressed sparse row graph: compact for millions of vessels.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <boost/graph/compressed_sparse_row_graph.hpp>

#include "formats/network.hpp"

namespace hemotree {

// Edge bundle: the vessel index, so that edge properties map onto the network's arrays.
struct VesselEdge {
  std::int32_t vessel = -1;
};
using NetworkGraph =
    boost::compressed_sparse_row_graph<boost::directedS, boost::no_property, VesselEdge>;

NetworkGraph make_graph(const Network& net);

// Generation of every vessel: vessels leaving a node that no vessel enters are generation
// 0; each vessel downstream is one more than the vessel that feeds it (breadth-first).
// Vessels no such path reaches (written against the flow, or in a closed loop) count from
// the nearest reached node in either direction, or else from their part's lowest node: every
// vessel gets a generation >= 0.
std::vector<std::int32_t> generations_from_inlets(const Network& net);

// Checks that the network is one rooted tree: a single inlet vessel, every node entered by
// at most one vessel, every vessel reached from the inlet. Throws InputError naming the
// first vessel at fault. Returns the index of the root vessel.
std::size_t check_rooted_tree(const Network& net);

// For every vessel, the indices of the vessels leaving its distal node (CSR layout:
// children[offset[v] .. offset[v+1]) ).
struct Children {
  std::vector<std::int64_t> offset;
  std::vector<std::int32_t> index;
};
Children children_of(const Network& net);

// Vessels breadth first from the root: every parent before its daughters.
std::vector<std::int32_t> breadth_first_order(const Children& children, std::size_t root);
// The same from several roots (a forest), the roots first in their order.
std::vector<std::int32_t> breadth_first_order(const Children& children, std::span<const std::int32_t> roots);

// Vessels leaving a node that no vessel enters, in index order: a forest's roots.
std::vector<std::int32_t> inlet_vessels(const Network& net);

}  // namespace hemotree
