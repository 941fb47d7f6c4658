// Steady flow through a network of rigid vessels at their reference diameters: Poiseuille's
// law with the apparent viscosity of the blood (Pries in vivo or Newtonian) in every vessel,
// the outlets' resistances to their outflow pressures, and the mean inflow at the inlet.
// vprune checks its outlets with it; hemosolve starts from it instead of from rest.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "formats/network.hpp"
#include "physics/viscosity_table.hpp"
#include "physics/tube_law.hpp"

namespace hemotree {

class FlowNetwork;  // network_flow/flow_network.hpp

struct SteadyFlow {
  std::vector<double> flow;           // per vessel, positive from -> to [m^3/s]
  std::vector<double> node_pressure;  // [Pa]
  double inlet_pressure = 0;          // at the inlet vessel's `from` node [Pa]
};

// Poiseuille resistance of every vessel [Pa s/m^3] with the blood's apparent viscosity at
// its reference diameter and its velocity profile (alpha); a tapered vessel's integrated
// along it (physics/poiseuille.hpp).
std::vector<double> vessel_resistances(const Network& net, const Blood& blood);
// The same with each vessel's own discharge hematocrit (empty: the blood's in every vessel),
// in parallel blocks of `threads` (the same numbers, and an error's message, for any count).
std::vector<double> vessel_resistances(const Network& net, const Blood& blood, std::span<const double> hematocrit,
                                       int threads = 1);

// One vessel's (the function of every vessel of vessel_resistances, the blood's hematocrit),
// and at the vessel's own hematocrit (hematocrit: per vessel; empty: the blood's).
double vessel_resistance(const Network& net, const Blood& blood, std::size_t v);
double vessel_resistance(const Network& net, const Blood& blood, std::size_t v, std::span<const double> hematocrit);

// The steady flow's boundary rows, after its checks (InputError, SettingError "pressure_at",
// as solve_steady_flow's below): per node the outlets' 1/R to ground (shunt; a unit shunt at a
// node no vessel touches), the flows in and the outlets' p_out / R (inflow), the prescribed
// pressures; the node where the tree's inflow enters (-1: none). What solve_steady_flow
// solves with, and a rank's share of it (distributed/).
struct SteadyRows {
  std::vector<double> shunt, inflow, pressure;
  std::vector<unsigned char> prescribed;
  std::int64_t inlet_node = -1;
};
SteadyRows steady_rows(const Network& net);
// The rows of a part of a network whose whole steady_rows checked (a rank's slice of it,
// formats/network_slice.hpp): its own boundaries' rows alone (the inlet's node, where the part
// holds the inlet, marked but given no flow), none of the whole network's checks.
SteadyRows boundary_rows(const Network& part);
// The refusal of a system found singular at `node` (a part whose pressure nothing fixes).
[[noreturn]] void refuse_floating_part(const Network& net, std::int64_t node);

// Thevenin equivalent of what lies beyond a vessel's distal node: the flow into it is
// (p - pressure) / resistance.
struct Equivalent {
  double resistance = 0;  // [Pa s/m^3]
  double pressure = 0;    // [Pa]
};

// For every vessel of a rooted tree, what lies beyond its distal node (its daughters'
// subtrees in parallel, or its outlet) reduced to a Thevenin equivalent: series and parallel
// reduction from the leaves up, O(vessels). Throws InputError where check_rooted_tree does.
std::vector<Equivalent> reduce_beyond(const Network& net, const std::vector<double>& resistance);

// The outlet of every vessel (its index in net.outlets, -1 for none), having checked that the
// outlets sit on exactly the terminal vessels (those whose distal node no vessel leaves), one
// each, none a reflection outlet (which has no steady resistance) and each with a positive
// resistance: InputError otherwise, naming the vessel.
std::vector<std::int32_t> steady_outlets(const Network& net);

// Solves the steady flow of a network fed by inlet_flow [m^3/s] at its inlet vessel's `from`
// node (net.inlet's vessel; without one, the only vessel that no vessel feeds), every terminal
// vessel ending in an outlet (RCR or R: their total resistance to p_out). The network may
// have loops: its node pressures solve the nodal system (network_flow/nodal_system.hpp) of
// the vessels' conductances 1/R and the outlets' shunts 1/R to p_out, and each vessel's flow
// is its pressure drop over R. On a tree that is the elimination from the leaves up, O(vessels)
// and exact to rounding (as the series/parallel reduction it replaces); with loops, a sparse
// Cholesky factorisation. InputError where steady_outlets throws, for an inlet that another
// vessel feeds, a vessel that no vessel feeds and does not start at the inlet's node (an
// open end with neither inflow nor outlet), a vessel not connected to the inlet, or a
// network with no outlet.
// beyond, when given, receives reduce_beyond's equivalents (a pass of its own, for a rooted
// tree only: InputError on any other network).
SteadyFlow solve_steady_flow(const Network& net, const std::vector<double>& resistance,
                             double inlet_flow, std::vector<Equivalent>* beyond = nullptr);

// The same with the network's own blood (defaults if absent) and inlet (mean flow).
SteadyFlow solve_steady_flow(const Network& net);

// solve_steady_flow for one network and many sets of resistances (an iteration's passes): the
// nodal system of the node pressures (network_flow/flow_network.hpp: each vessel an edge of
// conductance 1/R, each outlet a shunt 1/R to its outflow pressure, flows injected at their
// nodes, prescribed pressures eliminated), its graph, boundary rows and checks made once and
// its pattern analysed once (a sparse Cholesky's ordering on a network with loops); each solve
// refactorises. The same numbers as solve_steady_flow, bit for bit. The network must outlive it.
class SteadyFlowSolver {
 public:
  explicit SteadyFlowSolver(const Network& net);  // the checks: InputError as solve_steady_flow
  ~SteadyFlowSolver();
  SteadyFlow solve(const std::vector<double>& resistance, double inlet_flow);
  // Into `s`, its arrays kept where they have their size: an iteration's solves then touch no
  // fresh memory (on the full tree, 90 MB a sweep made afresh were half the iteration's time).
  void solve(const std::vector<double>& resistance, double inlet_flow, SteadyFlow& s);
  void set_threads(int threads);  // a tree's elimination (the same numbers for any count)

 private:
  const Network& net_;
  SteadyRows rows_;
  std::vector<double> conductance_;        // per vessel
  std::vector<double> inflow_with_inlet_;  // per node: the rows' inflow and the inlet's
  std::unique_ptr<FlowNetwork> system_;
};

// The steady state of the pulse solver's own equations under the mean inflow: every vessel
// compliant, at the lumen its tube law gives at its mean pressure, with the viscosity of that
// lumen (the rigid solution above keeps the reference lumens: in the default network it puts
// the inlet at 68.6 mmHg, the distended vessels at 62.6 mmHg). Fixed-point
// iteration from the rigid solution: resistances at the distended lumens, then flows and
// pressures again, until no pressure changes by more than 1e-9 of the inlet's (about 20
// sweeps; the nodal system is analysed once and refactorised each sweep). resistance, when
// given, receives the final ones. Throws InputError where solve_steady_flow does, or where a
// lumen collapses.
// blood: the run's (its rheology may differ from the file's). threads: for a tree's sweeps
// (the same numbers for any count).
SteadyFlow solve_distended_steady_flow(const Network& net, const Blood& blood, std::span<const TubeLaw> laws,
                                       const ViscosityTable& viscosity, double inlet_flow,
                                       std::vector<double>* resistance = nullptr, int threads = 1);

}  // namespace hemotree
