// A reflection outlet: the wave entering the vessel is -R_t times the wave leaving it, both
// measured from the rest state (A0, Q0); R_t = 0 lets waves leave without reflection.
//
//   1D end:  Q* - Q = lambda_in (A* - A) (the outgoing characteristic, kept) and
//            w_in = -R_t w_out, w_k = l_k(U0) . (U* - U0) (physics/riemann.hpp's
//            reflection_state).
//   0D rows, steady: none; a reflection has no resistance, so a 0D vessel or a steady run
//            refuses it, naming the vessel or node.
// Written for a distal end, Q* along the vessel (out of the network).
#pragma once

#include "physics/riemann.hpp"
#include "physics/tube_law.hpp"

namespace hemotree {

struct ReflectionOutlet {
  double coefficient = 0;               // R_t in [-1, 1]
  double rest_area = 0, rest_flow = 0;  // A0 [m^2], Q0 [m^3/s] along the vessel

  EndState end_state(const TubeLaw& law, double a, double q) const {
    return reflection_state(law, a, q, rest_area, rest_flow, coefficient);
  }
};

}  // namespace hemotree
