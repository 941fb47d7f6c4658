// A resistance outlet (R): the vasculature beyond the end as one resistance R to the
// outflow pressure p_out.
//
//   1D end:  p(A*) - p_out = R Q*, with the characteristic leaving the vessel kept,
//            Q* - Q = lambda_in (A* - A) (pulse/riemann.hpp's resistance_state).
//   0D rows: a shunt 1/R from its node to p_out (pulse/lumped_boundary_rows.cpp).
//   steady:  the same shunt in the nodal system (steady/steady_flow.cpp).
// Written for a distal end, Q* along the vessel (out of the network); at a proximal end the
// caller passes the mirrored trace and negates the flow back.
#pragma once

#include "physics/tube_law.hpp"
#include "pulse/boundaries/lumped_rows.hpp"
#include "pulse/riemann.hpp"

namespace hemotree {

struct ResistanceOutlet {
  double resistance = 0;  // R [Pa s/m^3]
  double p_out = 0;       // [Pa]

  EndState end_state(const TubeLaw& law, double a, double q) const {
    return resistance_state(law, a, q, resistance, p_out);
  }
  // Its 0D row: a shunt 1/R to p_out.
  LumpedShunt lumped_shunt() const { return {1 / resistance, p_out}; }
};

}  // namespace hemotree
