// What a boundary condition adds to the 0D system at a node of 0D vessels
// (pulse/lumped_vessels, pulse/lumped_boundary_rows.cpp): a shunt of conductance G from the
// node to a pressure p_s (the current G (p_s - p_i) enters the node), or, for an RCR, an edge
// R1 to a capacitor node of its own with compliance C and a shunt 1/R2 to p_out.
#pragma once

namespace hemotree {

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
