// openBF's YAML network models (github.com/INSIGNEO/openBF): vessels with sn/tn, L, R0 or
// Rp/Rd, E, h0, inlet file, wk2/wk3 outlets, blood. Read with yaml-cpp. Mapping:
// docs/import.md.
#pragma once

#include <string>

#include "exchange/foreign_format.hpp"
#include "formats/output_stream.hpp"

namespace hemotree {

// Throws InputError "FILE:LINE: what is wrong" for a malformed model or one using a feature
// hemotree does not model; IoError when the file or its inlet file cannot be read.
Network read_openbf(const std::string& path, const ImportOptions& options);
// Writes an openBF YAML model; the inlet's table goes to inlet_path (two columns t, Q),
// named in the YAML relative to the YAML's folder.
void write_openbf(const Network& net, OutputStream& out, const std::string& inlet_path);

}  // namespace hemotree
