// T. W. Secomb's network.dat (NetFlow, Greens): segments with diameters in um, nodes with
// coordinates in um, boundary nodes with pressures [mmHg] or flows [nl/min] and inflow
// hematocrits. Mapping: docs/import.md.
#pragma once

#include <string>

#include "exchange/foreign_format.hpp"
#include "formats/output_stream.hpp"

namespace hemotree {

// Throws InputError "FILE:LINE: what is wrong" for a malformed file; IoError when unreadable.
Network read_secomb(const std::string& path, const ImportOptions& options);
// Writes the network in network.dat form (boundary nodes from its node boundaries; a
// boundary the format cannot hold, an RCR, is InputError naming the node).
void write_secomb(const Network& net, OutputStream& out);

}  // namespace hemotree
