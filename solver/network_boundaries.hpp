// Where the 1D vessels' ends meet: junctions, the inlet, the outlets, and the nodes of 0D
// vessels (coupling ends), in flat lists the solver sweeps every stage. Built once from the
// network; refuses, naming the vessel, a network it cannot run.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "formats/network.hpp"
#include "solver/riemann.hpp"
#include "solver/vessel_equations.hpp"

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
  std::vector<VesselEnd> junction_ends;
  std::vector<std::int64_t> junction_node;  // node id, for messages

  VesselEnd inlet;  // vessel -1: the inlet vessel is 0D
  Waveform inflow;

  // 1D vessel ends at a node where 0D vessels end: the node's pressure is given to them.
  struct CoupledEnd {
    VesselEnd end;
    std::int64_t node = 0;  // network node index
  };
  std::vector<CoupledEnd> coupled;

  struct OutletEnd {
    VesselEnd end;
    Outlet outlet;
    std::int32_t index = -1;      // its position in the network's outlets
    std::int32_t capacitor = -1;  // index of its RCR state, or -1
    double rest_area = 0, rest_flow = 0;  // for the reflection coefficient
  };
  std::vector<OutletEnd> outlets;
  std::size_t capacitors = 0;

  // The end states of the last solve, per vessel end: [2 v] proximal, [2 v + 1] distal.
  std::vector<EndState> end_state;
};

// Vessel v's elements are first_element[v] .. first_element[v] + elements_per_vessel - 1;
// zero_d[v]: vessel v is 0D (no elements: its ends belong to solver/lumped_vessels).
NetworkBoundaries build_boundaries(const Network& net, const std::vector<std::int32_t>& first_element,
                                   int elements_per_vessel, const std::vector<bool>& zero_d);

}  // namespace hemotree
