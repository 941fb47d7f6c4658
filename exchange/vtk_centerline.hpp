// Vessel centerlines as VTK PolyData (VMTK's vmtkcenterlines output, .vtp XML in ascii,
// binary or appended encodings, zlib-compressed or not; legacy .vtk ascii): polylines with a
// per-point radius array. Each polyline between branch points becomes one vessel of the
// polyline's arc length and mean radius. Mapping: docs/import.md.
#pragma once

#include <string>

#include "exchange/foreign_format.hpp"

namespace hemotree {

struct CenterlineOptions {
  std::string radius_array = "MaximumInscribedSphereRadius";  // VMTK's name
};

Network read_vtk_centerline(const std::string& path, const ImportOptions& options,
                            const CenterlineOptions& centerline = {});

}  // namespace hemotree
