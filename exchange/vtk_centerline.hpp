// Vessel centerlines as VTK PolyData (VMTK's vmtkcenterlines output, .vtp XML in ascii,
// binary or appended encodings, zlib-compressed or not; legacy .vtk ascii): polylines with a
// per-point radius array. Polylines meet where they share a point (the same point id, or
// coincident coordinates); each chain of points between junctions and ends becomes one
// vessel of the chain's arc length and length-weighted mean radius. Mapping: docs/import.md.
#pragma once

#include <string>

#include "exchange/foreign_format.hpp"

namespace hemotree {

struct CenterlineOptions {
  std::string radius_array = "MaximumInscribedSphereRadius";  // VMTK's name (point data)
  // Metres per unit of the file's coordinates and radii. VTK files carry no unit; VMTK
  // models are usually in mm (vimport --unit mm gives 1e-3). Default: metres, as everywhere
  // in hemotree; a model in mm read as metres fails the diameter range with a hint.
  double length_unit = 1.0;
};

// Throws InputError "FILE: element ...: what is wrong" (XML) or "FILE:LINE: what is wrong"
// (legacy) for a malformed file or one that is not a centerline network; IoError when the
// file cannot be read.
Network read_vtk_centerline(const std::string& path, const ImportOptions& options,
                            const CenterlineOptions& centerline = {});

}  // namespace hemotree
