// A prescribed flow Q_in(t) into the network at a vessel end (negative: out of it).
//
//   1D end:  Q* = Q_in at a proximal end (Q* = -Q_in at a distal one: the flow along the
//            vessel), with the characteristic leaving the vessel kept,
//            Q* - Q = lambda_in (A* - A) (physics/riemann.hpp).
//   0D rows: a current Q_in into its node (pulse/lumped_boundary_rows.cpp keeps its node).
//   steady:  Q_in's period mean injected at its node, b_i += Q_in.
#pragma once

#include <cstddef>

#include "boundaries/system_rows.hpp"
#include "physics/riemann.hpp"
#include "physics/tube_law.hpp"

namespace hemotree {

struct FlowInlet {
  double inflow = 0;  // Q_in(t) [m^3/s], into the network (its mean in a steady row)

  // The end state from the trace (a, q) of the vessel's end; a distal end takes the
  // condition on the mirrored trace (a, -q), its flow negated back (x -> -x symmetry).
  EndState end_state(const TubeLaw& law, double a, double q, bool distal) const {
    if (!distal) return inflow_state(law, a, q, inflow);
    EndState u = inflow_state(law, a, -q, inflow);
    u.flow = -u.flow;
    return u;
  }
  void add_steady_row(NodalRows& rows, std::size_t node) const { rows.inflow[node] += inflow; }
};

}  // namespace hemotree
