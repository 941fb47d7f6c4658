// The Riemann problems of the 1D model: between two elements of a vessel (an upwind flux),
// and at the ends of vessels, where the characteristic leaving each vessel is kept and the
// node supplies the rest: a junction (mass and total pressure conserved), a prescribed
// inflow, a resistance or RCR outlet, or a reflection coefficient.
//
// Characteristics are linearised about the trace inside the vessel: the state U* at the end
// satisfies l_out . (U* - U) = 0 with the left eigenvector l_out = (-lambda_in, 1) of the
// flux Jacobian, i.e. Q* - Q = lambda_in (A* - A). It holds for any alpha (the exact Riemann
// invariants u +- 4c exist only for alpha = 1), and its error is quadratic in the jump
// between the trace and the end state, which vanishes as the solution converges.
#pragma once

#include <span>

#include "physics/tube_law.hpp"

namespace hemotree {

struct EndState {
  double area = 0, flow = 0;
};

// Upwind flux between a left state (a_l, q_l) and a right state: the Roe-type flux
// F* = (F_l + F_r)/2 - |H|(U_r - U_l)/2 with the Jacobian at the mean state.
void upwind_flux(const TubeLaw& law, double a_l, double q_l, double a_r, double q_r,
                 double& flux_area, double& flux_flow);

// The speed lambda_in of the characteristic entering a vessel at an end: forward speed at
// the proximal end, backward at the distal end.
double incoming_speed(const TubeLaw& law, double a, double q, bool distal);

// Prescribed inflow q_in at a vessel's proximal end.
EndState inflow_state(const TubeLaw& law, double a, double q, double q_in);

// Distal end into a resistance R to the pressure p_beyond: p(A*) - R Q* = p_beyond.
// (An RCR outlet is this with R = R1 and p_beyond the capacitor pressure.)
EndState resistance_state(const TubeLaw& law, double a, double q, double r, double p_beyond);

// An end at a node of 0D vessels (pulse/lumped_vessels): the end's total pressure
// p(A*) + rho u*^2 / 2, as at a junction, equals the node's p_node + r Q_in (the node's total
// pressure, where Q_in is the flow from the end into the node and r the node's response to
// it). distal: which end.
EndState pressure_state(const TubeLaw& law, double a, double q, double p_node, bool distal, double r = 0);

// Distal end with reflection coefficient rt of the wave leaving the vessel, measured from
// the rest state (a0, q0): rt = 0 lets waves leave without reflection.
EndState reflection_state(const TubeLaw& law, double a, double q, double a0, double q0, double rt);

// A junction of n vessel ends: traces (a, q) in, end states out; sign +1 for a vessel
// whose distal end meets the node (its flow enters the node), -1 for a proximal end.
// Newton on the areas: sum sign Q* = 0 and equal total pressure p + rho u^2 / 2.
// Returns false if Newton did not converge. out's areas, where positive, are taken as the
// first guess (the previous step's solution saves an iteration or two).
bool junction_state(std::span<const TubeLaw* const> laws, std::span<const double> a,
                    std::span<const double> q, std::span<const int> sign,
                    std::span<EndState> out);

}  // namespace hemotree
