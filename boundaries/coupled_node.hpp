// A 1D vessel's end at a node of 0D vessels (pulse/lumped_vessels): the coupled 0D node.
//
//   1D end:  the end's total pressure, as at a junction, is the node's,
//              p(A*) + rho u*^2 / 2 = P + r Q_in,   P = p(t) + p_dyn - r Q_held,
//            with p(t) the node's pressure at this point of the 0D step, p_dyn the kinetic
//            energy of its 0D vessels, r = 3/2 Z its response to the flow Q_in from the end
//            into it and Q_held that flow held over the step (docs/solver.md §10); the
//            characteristic leaving the vessel is kept (physics/riemann.hpp's pressure_state).
//   0D rows: Q_in, a current into the node (PulseState's coupled part).
#pragma once

#include "physics/tube_law.hpp"
#include "physics/riemann.hpp"

namespace hemotree {

struct CoupledNode {
  double pressure = 0;          // p(t) [Pa]
  double dynamic_pressure = 0;  // p_dyn [Pa]
  double response = 0;          // r [Pa s/m^3]
  double held_flow = 0;         // Q_held [m^3/s]

  EndState end_state(const TubeLaw& law, double a, double q, bool distal) const {
    return pressure_state(law, a, q, pressure + dynamic_pressure - response * held_flow, distal, response);
  }
  // Q_in: the end's flow into the node (an end state's flow is along the vessel).
  static double flow_into_node(const EndState& u, bool distal) { return distal ? u.flow : -u.flow; }
};

}  // namespace hemotree
