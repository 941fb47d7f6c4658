// Where the 1D vessels' ends meet: junctions, the boundary conditions at vessel ends (flows,
// pressures, outlets), and the nodes of 0D vessels (coupling ends), in flat lists the solver
// sweeps every stage. Built once from the network; refuses, naming the vessel or node, a
// network it cannot run.
//
// Boundary conditions sit at nodes where exactly one vessel ends, at either of its ends: the
// 1D equations are symmetric under x -> -x, Q -> -Q, so a condition written for one end
// (physics/riemann.hpp) acts at the other on the mirrored trace (A, -Q), its flow negated.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "formats/network.hpp"
#include "formats/run_boundaries.hpp"
#include "physics/riemann.hpp"

namespace hemotree {

// One end of a vessel: its distal end (the `to` node, right trace of its last element) or
// its proximal end (`from` node, left trace of its first element).
struct VesselEnd {
  std::int32_t vessel = 0;
  std::int32_t element = 0;
  bool distal = false;
};

struct NetworkBoundaries {
  // Junctions: ends of junction j are ends[offset[j] .. offset[j+1]).
  std::vector<std::int64_t> junction_offset{0};
  std::vector<std::int64_t> junction_node;  // node id, for messages
  std::vector<VesselEnd> junction_ends;

  // The run's boundary conditions (formats/run_boundaries.hpp), and per boundary whether its flow counts
  // as entering the network (the cycle's "in") or leaving it ("out"): a flow by the sign of
  // its mean, a pressure by its steady flow (PulseSolver sets it), an outlet always out.
  RunBoundaries list;
  std::vector<unsigned char> entering;

  // Prescribed flows and pressures at 1D ends (index: the boundary's place in list; slot: its
  // place in one_d_boundary).
  struct GivenEnd {
    VesselEnd end;
    std::int32_t index = -1;
    std::int32_t slot = -1;
  };
  std::vector<GivenEnd> flows, pressures;

  // 1D vessel ends at a node where 0D vessels end: the node's pressure is given to them.
  struct CoupledEnd {
    VesselEnd end;
    std::int64_t node = 0;  // network node index
  };
  std::vector<CoupledEnd> coupled;

  struct OutletEnd {
    VesselEnd end;
    Outlet outlet;
    std::int32_t index = -1;      // its place among the run's outlets
    std::int32_t boundary = -1;   // its place in list
    std::int32_t slot = -1;       // its place in one_d_boundary
    std::int32_t capacitor = -1;  // index of its RCR state, or -1
    // For the reflection coefficient: the rest area and the flow along the vessel there.
    double rest_area = 0, rest_flow = 0;
  };
  std::vector<OutletEnd> outlets;
  std::size_t capacitors = 0;
  // The boundaries at 1D ends (flows, pressures, outlets), by their places in list: the 1D
  // scheme integrates the volume through these alone (a full tree has two million boundaries,
  // nearly all at 0D vessels, whose volumes pulse/lumped_vessels sums once a step).
  std::vector<std::int32_t> one_d_boundary;

  // The end states of the last solve, per 1D element's end ([2 el] left, [2 el + 1] right;
  // only a vessel's ends are set): a 0D vessel has no elements and keeps none (on a full
  // tree, 32 B a vessel that were never written).
  std::vector<EndState> end_state;
  EndState& state_at(const VesselEnd& end) { return end_state[2 * static_cast<std::size_t>(end.element) + (end.distal ? 1 : 0)]; }
  const EndState& state_at(const VesselEnd& end) const {
    return end_state[2 * static_cast<std::size_t>(end.element) + (end.distal ? 1 : 0)];
  }
};

// Vessel v's elements are first_element[v] .. first_element[v] + elements_per_vessel - 1;
// zero_d[v]: vessel v is 0D (no elements: its ends, and boundaries there, belong to
// pulse/lumped_vessels).
NetworkBoundaries build_boundaries(const Network& net, const std::vector<std::int32_t>& first_element,
                                   int elements_per_vessel, const std::vector<bool>& zero_d);

}  // namespace hemotree
