// What a boundary condition adds to the two linear systems it takes part in, besides its 1D
// end state (physics/riemann.hpp):
//
//   steady (steady/steady_flow.cpp), per node i: a shunt conductance G_i to a source, the
//   current b_i injected, and whether its pressure is prescribed (and to what). Node i's row
//     sum_edges (p_i - p_j) / R_e + G_i p_i = b_i,   or p_i = P_i where prescribed.
//   0D (pulse/lumped_vessels, pulse/lumped_boundary_rows.cpp), at a node of 0D vessels: a
//   shunt of conductance G to a pressure p_s (the current G (p_s - p_i) enters the node), or,
//   for an RCR, an edge R1 to a capacitor node of its own with compliance C and a shunt 1/R2
//   to p_out.
#pragma once

#include <vector>

namespace hemotree {

// The steady nodal system's boundary rows, per node.
struct NodalRows {
  std::vector<double>& shunt;              // G_i [m^3/(Pa s)]
  std::vector<double>& inflow;             // b_i [m^3/s]
  std::vector<double>& pressure;           // P_i [Pa], where prescribed
  std::vector<unsigned char>& prescribed;  // per node
};

struct LumpedShunt {
  double conductance = 0;  // G [m^3/(Pa s)]
  double pressure = 0;     // p_s [Pa]
};

struct LumpedCapacitor {
  double edge_resistance = 0;  // R1 [Pa s/m^3], node to capacitor
  LumpedShunt shunt;           // 1/R2 to p_out
  double compliance = 0;       // C [m^3/Pa]
};

}  // namespace hemotree
