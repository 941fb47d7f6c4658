// A part of a network, for a process that holds only some of its vessels: a rank of a run
// over MPI ranks (issue 24, docs/scaling.md), which reads the whole topology (a partition
// needs every vessel's ends) and then only its own vessels' rows of every other column. From
// an HDF5 network file (docs/network-format.md), whose columns a slice reads chunk by chunk:
// the JSON form has no rows to seek to.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "formats/network.hpp"

namespace hemotree {

struct NetworkSlice {
  // The slice's vessels (in the whole network's order) and the nodes they touch (likewise),
  // numbered locally: from and to index its nodes, an outlet's vessel its vessels. It holds
  // the outlets of its vessels, the inlet where it holds the inlet's vessel, the boundaries
  // at its nodes, the blood and the provenance.
  Network net;
  std::vector<std::int32_t> vessel_row;  // per vessel of the slice, its row in the whole network
  std::vector<std::int32_t> node_row;    // per node of the slice, its row

  // The slice's node at a whole network's row; -1 where it holds none there.
  std::int32_t node_at(std::int32_t row) const;
};

// Whether path names an HDF5 file (by its eight signature bytes), which a slice may be read from.
bool is_hdf5_network_file(const std::string& path);

// The topology of the network at path (HDF5): every node's and vessel's id, every vessel's
// ends, the blood, inlet, boundaries at nodes and provenance; every other column empty (a
// Network holding only what partition/ and distributed/'s cut read). The checks of the whole
// reader on what it reads (unique ids, ends among the nodes, an inlet's vessel), in its words.
Network read_network_topology(const std::string& path);

// The same topology of a network held whole (what read_network_topology reads of its file).
Network topology_of(const Network& whole);

// The vessels at rows `vessels` (increasing) of topology's, read from the same file: every
// value checked as the whole reader checks it, named by the row of the file.
NetworkSlice read_network_slice(const std::string& path, const Network& topology, std::span<const std::int32_t> vessels);

// The same slice of a network held whole (what read_network_slice reads from its file).
NetworkSlice slice_of(const Network& whole, std::span<const std::int32_t> vessels);

}  // namespace hemotree
