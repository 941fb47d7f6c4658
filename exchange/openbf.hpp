// openBF's YAML network models (github.com/INSIGNEO/openBF): vessels with sn/tn, L, R0 or
// Rp/Rd, E, h0, inlet file, wk2/wk3 outlets, blood. Read with yaml-cpp. Mapping:
// docs/import.md.
#pragma once

#include <string>

#include "exchange/foreign_format.hpp"
#include "formats/output_stream.hpp"

namespace hemotree {

// Which model a file means where openBF's code and its documentation part (docs/import.md):
// `code` builds what openBF 2.x computes, noting each place it departs from the documentation;
// `documented` reads the keys as openBF's documentation describes them.
enum class OpenbfReading { code, documented };

// Throws InputError "FILE:LINE: what is wrong" for a malformed model or one using a feature
// hemotree does not model, or for a model or inlet file that is not a regular file of at most
// 64 MB; IoError when the file or its inlet file cannot be read.
Network read_openbf(const std::string& path, const ImportOptions& options,
                    OpenbfReading reading = OpenbfReading::code);
// Writes an openBF YAML model into out (the caller commits it); the inlet's table goes to
// inlet_path (two columns t, Q, from 0 to the period; written and committed here), named in
// the YAML relative to the YAML's folder. Throws InputError "node ID: ..." or "vessel ID: ..."
// for what openBF cannot express: pressure boundaries, a second inflow, an inflow hematocrit,
// resistance outlets, RCR outlets with R1 or R2 = 0, a terminal vessel without an outlet, a
// velocity profile that is not a whole gamma.
void write_openbf(const Network& net, OutputStream& out, const std::string& inlet_path);

}  // namespace hemotree
