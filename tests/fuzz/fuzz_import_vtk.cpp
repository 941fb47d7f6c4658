// vimport vtk on hostile bytes: read_vtk_centerline on the input, which picks legacy .vtk or
// XML .vtp by its first bytes (ascii, binary, appended, zlib). Lengths in mm, as VMTK writes
// them; the radius array is VMTK's MaximumInscribedSphereRadius, or "Radius" in a file
// without that name. An accepted network must be written as vnet and read back the same
// (vimport's output; VTK has no writer of centerlines to go back to). A refusal is
// InputError, nothing else.
#include <cstdint>
#include <string>
#include <string_view>

#include "exchange/vtk_centerline.hpp"
#include "import_support.hpp"

using namespace hemotree;
using namespace hemotree::fuzz;

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  init_import_harness();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const auto input = scratch() / "centerline.vtp";
  write_file(input, bytes);
  CenterlineOptions centerline;
  centerline.length_unit = 1e-3;
  if (bytes.find(centerline.radius_array) == std::string_view::npos) centerline.radius_array = "Radius";
  const auto net = refused_or("read_vtk_centerline",
                              [&] { return read_vtk_centerline(input.string(), quiet_options(), centerline); });
  if (!net) return 0;
  check_vnet_round_trip(*net, "vtk");
  return 0;
}
