// The largest connected part of a network alone: networks from imaging come with fragments
// around the one network worth solving, each of which would need boundary conditions of its own.
#pragma once

#include <cstddef>
#include <string>

#include "formats/network.hpp"

namespace hemotree {

// What keeping the largest part left out.
struct DroppedParts {
  std::size_t parts = 0;
  std::size_t vessels = 0;
  std::size_t nodes = 0;           // including nodes no vessel meets
  std::size_t boundary_nodes = 0;  // conditions at the dropped nodes (inlet and outlets included)
  // The kept vessels' generations lay beyond the kept count (the format's bound) and were
  // counted again from the part's inlets (generations_from_inlets).
  bool generations_recounted = false;
};

// The part with the most vessels (of equal ones, the one with the lowest vessel id), with every
// per-vessel and per-node field, the boundary conditions at its nodes (its inlet and outlets in
// the tree form), the blood, provenance and unknown members. Ids stay as they were; only the
// array positions close up. InputError for a network without vessels.
Network largest_connected_part(const Network& net, DroppedParts* dropped = nullptr);

// For a note: "kept the largest connected part, 120 vessels and 98 nodes; dropped 4 parts:
// 23 vessels, 30 nodes, 6 boundary nodes" (or "the network is one part: nothing dropped").
std::string describe(const Network& kept, const DroppedParts& dropped);

}  // namespace hemotree
