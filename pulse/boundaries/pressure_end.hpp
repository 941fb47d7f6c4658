// A prescribed pressure p(t) at a vessel end's node.
//
//   1D end:  the end's total pressure is the node's, p(A*) + rho u*^2 / 2 = p(t), with the
//            characteristic leaving the vessel kept, Q* - Q = lambda_in (A* - A)
//            (pulse/riemann.hpp's pressure_state, as at a junction).
//   0D rows: a shunt far stiffer than the node's vessel to p(t), a Dirichlet condition to
//            1e-10 of the vessel's drop (pulse/lumped_boundary_rows.cpp).
//   steady:  the node's pressure eliminated from the nodal system (steady/steady_flow.cpp).
#pragma once

#include "physics/tube_law.hpp"
#include "pulse/riemann.hpp"

namespace hemotree {

struct PressureEnd {
  double pressure = 0;  // p(t) [Pa]

  EndState end_state(const TubeLaw& law, double a, double q, bool distal) const {
    return pressure_state(law, a, q, pressure, distal);
  }
};

}  // namespace hemotree
