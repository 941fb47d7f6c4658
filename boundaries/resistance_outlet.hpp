// A resistance outlet (R): the vasculature beyond the end as one resistance R to the
// outflow pressure p_out.
//
//   1D end:  p(A*) - p_out = R Q*, with the characteristic leaving the vessel kept,
//            Q* - Q = lambda_in (A* - A) (physics/riemann.hpp's resistance_state).
//   0D rows: a shunt 1/R from its node to p_out.
//   steady:  the same shunt in the nodal system, Q = (p_i - p_out) / R, so G_i += 1/R and
//            b_i += p_out / R.
//   harmonic: its impedance Z(w) = R (harmonic/linear_periodic.cpp).
// Written for a distal end, Q* along the vessel (out of the network); at a proximal end the
// caller passes the mirrored trace and negates the flow back.
#pragma once

#include <complex>
#include <cstddef>

#include "boundaries/system_rows.hpp"
#include "physics/riemann.hpp"
#include "physics/tube_law.hpp"

namespace hemotree {

struct ResistanceOutlet {
  double resistance = 0;  // R [Pa s/m^3]
  double p_out = 0;       // [Pa]

  EndState end_state(const TubeLaw& law, double a, double q) const {
    return resistance_state(law, a, q, resistance, p_out);
  }
  LumpedShunt lumped_shunt() const { return {1 / resistance, p_out}; }
  std::complex<double> impedance(double /*omega*/) const { return resistance; }
  void add_steady_row(NodalRows& rows, std::size_t node) const {
    rows.shunt[node] += 1 / resistance;
    rows.inflow[node] += p_out / resistance;
  }
};

}  // namespace hemotree
