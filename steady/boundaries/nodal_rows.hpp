// The rows a boundary condition adds to the steady flow's nodal system (steady/steady_flow.cpp):
// per node i, a shunt conductance G_i to a source, the current b_i injected, and whether its
// pressure is prescribed (and to what). Node i's row reads
//   sum_edges (p_i - p_j) / R_e + G_i p_i = b_i,   or p_i = P_i where prescribed.
// Each condition's row is in this folder under the name of its pulsatile type
// (pulse/boundaries/): steady/ sits below pulse/, so one type cannot carry both.
#pragma once

#include <cstddef>
#include <vector>

namespace hemotree::steady {

struct NodalRows {
  std::vector<double>& shunt;              // G_i [m^3/(Pa s)]
  std::vector<double>& inflow;             // b_i [m^3/s]
  std::vector<double>& pressure;           // P_i [Pa], where prescribed
  std::vector<unsigned char>& prescribed;  // per node
};

}  // namespace hemotree::steady
