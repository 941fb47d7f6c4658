// Transport grids built in code for the transport tests (transport/): a vessel of slices
// between two boundaries, and the face volumes of a flow along it.
#pragma once

#include <vector>

#include "transport/transport_grid.hpp"

namespace hemotree::test_grids {

// A vessel of n slices between boundary 0 (at its start) and boundary 1 (at its end); face i
// is the left face of slice i, face n the right end. k: the Fahraeus parameter of its lumen.
inline TransportGrid vessel(int n, double k = 1, double diameter = 10e-6) {
  TransportGrid g;
  g.boundaries = 2;
  for (int i = 0; i < n; ++i) g.add_cell(-1, k);
  g.add_face(0, TransportGrid::boundary_side(0), 0, diameter);  // positive: out to boundary 0
  for (int i = 0; i + 1 < n; ++i) g.add_face(i, i + 1, 0, diameter);
  g.add_face(n - 1, TransportGrid::boundary_side(1), 0, diameter);
  return g;
}

// The face volumes of a step that passes q_dt along the vessel (face 0 is signed against it:
// positive leaves the vessel at its start).
inline std::vector<double> along(int n, double q_dt) {
  std::vector<double> v(static_cast<std::size_t>(n) + 1, q_dt);
  v[0] = -q_dt;
  return v;
}

}  // namespace hemotree::test_grids
