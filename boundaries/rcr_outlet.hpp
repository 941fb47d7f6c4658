// A three-element Windkessel outlet (RCR): R1 from the end to a capacitor C at pressure
// p_c, and R2 from there to the outflow pressure p_out.
//
//   1D end:     p(A*) - p_c = R1 Q*, with the characteristic leaving the vessel kept,
//               Q* - Q = lambda_in (A* - A) (physics/riemann.hpp's resistance_state);
//   capacitor:  C dp_c/dt = Q* - (p_c - p_out) / R2.
//   Without compliance (C = 0) R1 and R2 are in series: p(A*) - p_out = (R1 + R2) Q*.
//   0D rows: R1 an edge to a capacitor node with C and a shunt 1/R2 to p_out.
//   steady:  the capacitor carries nothing, so R1 and R2 are in series, a shunt
//            1/(R1 + R2) to p_out.
//   harmonic: its impedance Z(w) = R1 + R2 / (1 + i w R2 C) (harmonic/linear_periodic.cpp).
// Written for a distal end, Q* along the vessel (out of the network).
#pragma once

#include <complex>
#include <cstddef>

#include "boundaries/resistance_outlet.hpp"
#include "boundaries/system_rows.hpp"
#include "physics/riemann.hpp"
#include "physics/tube_law.hpp"

namespace hemotree {

struct RcrOutlet {
  double r1 = 0, c = 0, r2 = 0;  // [Pa s/m^3], [m^3/Pa], [Pa s/m^3]
  double p_out = 0;              // [Pa]

  // The end state against the capacitor's pressure p_c.
  EndState end_state(const TubeLaw& law, double a, double q, double p_c) const {
    return resistance_state(law, a, q, r1, p_c);
  }
  // dp_c/dt from the end's flow Q* and the capacitor's pressure p_c.
  double capacitor_rate(double q_star, double p_c) const { return (q_star - (p_c - p_out) / r2) / c; }
  // With no compliance: R1 + R2 in series to p_out.
  EndState series_end_state(const TubeLaw& law, double a, double q) const { return in_series().end_state(law, a, q); }
  // Its 0D rows: R1 to a capacitor node of its own, or, with no compliance, a shunt
  // 1/(R1 + R2) to p_out.
  LumpedCapacitor lumped_capacitor() const { return {r1, {1 / r2, p_out}, c}; }
  LumpedShunt series_lumped_shunt() const { return in_series().lumped_shunt(); }
  void add_steady_row(NodalRows& rows, std::size_t node) const { in_series().add_steady_row(rows, node); }
  std::complex<double> impedance(double omega) const { return r1 + r2 / std::complex<double>(1.0, omega * r2 * c); }

 private:
  ResistanceOutlet in_series() const { return {r1 + r2, p_out}; }
};

}  // namespace hemotree
