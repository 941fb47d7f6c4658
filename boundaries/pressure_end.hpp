// A prescribed pressure p(t) at a vessel end's node.
//
//   1D end:  the end's total pressure is the node's, p(A*) + rho u*^2 / 2 = p(t), with the
//            characteristic leaving the vessel kept, Q* - Q = lambda_in (A* - A)
//            (physics/riemann.hpp's pressure_state, as at a junction).
//   0D rows: a shunt far stiffer than the node's vessel to p(t), a Dirichlet condition to
//            1e-10 of the vessel's drop (held_shunt; pulse/lumped_vessels.cpp's predict
//            sizes it each step from the node's compliance).
//   steady:  the node's pressure is the period mean, p_i = P, eliminated from the system.
#pragma once

#include <cstddef>

#include "boundaries/system_rows.hpp"
#include "physics/riemann.hpp"
#include "physics/tube_law.hpp"

namespace hemotree {

struct PressureEnd {
  double pressure = 0;  // p(t) [Pa] (its mean in a steady row)

  EndState end_state(const TubeLaw& law, double a, double q, bool distal) const {
    return pressure_state(law, a, q, pressure, distal);
  }
  // The 0D shunt that holds the node: 1e10 times what else reaches it, so that the pressure
  // its neighbour sees departs from p by 1e-10 of its vessel's drop; reach is the node's
  // vessel conductance at rest plus its compliance's C / dt (times 3/2, the BDF2 weight).
  LumpedShunt held_shunt(double reach) const { return {1e10 * reach, pressure}; }
  void add_steady_row(NodalRows& rows, std::size_t node) const {
    rows.prescribed[node] = 1;
    rows.pressure[node] = pressure;
  }
};

}  // namespace hemotree
