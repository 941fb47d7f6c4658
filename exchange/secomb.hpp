// T. W. Secomb's network.dat (NetFlow, Greens): segments with diameters in um, nodes with
// coordinates in um, boundary nodes with pressures [mmHg] or flows [nl/min] and inflow
// hematocrits. Read as NetFlow's input.cpp lays it out; mapping, assumptions and messages:
// docs/import.md.
#pragma once

#include <string>

#include "exchange/foreign_format.hpp"
#include "formats/output_stream.hpp"

namespace hemotree {

// Segments of type 4 or 5 become vessels (lengths: the distance between their nodes),
// boundary nodes become NodeBoundary (flows positive into the network, as NetFlow takes
// them; the hematocrit kept where blood may enter), generations are counted breadth first
// from the inflow nodes (the networks have loops); walls by fill_missing_walls, blood left
// unset (the file has none). Every assumption goes to options.note.
// Throws InputError "FILE:LINE: what is wrong" for a malformed file; IoError when unreadable.
Network read_secomb(const std::string& path, const ImportOptions& options);
// Writes the network in network.dat form: segments of type 5, coordinates in um, boundary
// nodes from node_boundaries(). Throws InputError, before writing anything, for what the
// format cannot hold: no coordinates, a curved or tapered vessel, an outlet model (RCR, R,
// reflection), a time-varying boundary, a boundary at an inner node, an id beyond 32 bits.
void write_secomb(const Network& net, OutputStream& out);

}  // namespace hemotree
