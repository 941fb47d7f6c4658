// What one rank steps of a run's 1D vessels when they are spread over the ranks (docs/scaling.md,
// "1D vessels across a cut"), and what it exchanges with the others at every evaluation of the
// DG rate.
//
// Each rank steps its own vessels' elements. A junction whose ends lie on several ranks is
// solved on each of them, alike: the junction's Riemann problem reads the inner traces (A, Q)
// of all its ends, so before it each rank sends the traces of its own ends there to every
// other rank with an end at that junction, and receives theirs. Every rank then holds the
// same numbers at the junction and solves it in the same order: the one-process run's bits,
// with one message each way per neighbouring rank and evaluation.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "pulse/network_boundaries.hpp"

namespace hemotree {

// Consecutive rows of the element arrays of one degree: a degree's block, or the part of it
// that one rank steps.
struct ElementRun {
  int degree = 0;
  std::int64_t first = 0, count = 0;
};

struct OneDCut {
  std::vector<ElementRun> runs;          // the rows it steps, block by block
  std::vector<std::int64_t> junctions;   // the junctions with an end of its own, increasing
  // Per other rank it shares a junction with (by rank): its own ends sent there, and that
  // rank's ends received, each junction after junction, a junction's ends in its order.
  struct Neighbour {
    int rank = 0;
    std::vector<VesselEnd> send, receive;
  };
  std::vector<Neighbour> neighbours;
  std::vector<int> ranks() const {
    std::vector<int> r;
    for (const Neighbour& n : neighbours) r.push_back(n.rank);
    return r;
  }
};

// The 1D ends coupled to 0D nodes (NetworkBoundaries::coupled) whose node another rank holds:
// per such rank, this rank's ends at its nodes (`ends`: their held inflows and volumes go
// there, the node's pressures come back) and its ends at this rank's nodes (`nodes`), each in
// the coupled ends' order. Each step: the held inflows out, the nodes' start and predicted
// pressures, impedance and dynamic pressure back, the volumes let through out (and, between
// coupling passes, the mean inflows out and the new predictions back).
struct CouplingCut {
  struct Neighbour {
    int rank = 0;
    std::vector<std::int32_t> ends, nodes;
  };
  std::vector<Neighbour> neighbours;
  std::vector<int> ranks() const {
    std::vector<int> r;
    for (const Neighbour& n : neighbours) r.push_back(n.rank);
    return r;
  }
};

// node_rank: per network node, the rank of the 0D vessels there (-1: none).
CouplingCut coupling_cut(const NetworkBoundaries& ends, std::span<const std::int32_t> vessel_rank,
                         std::span<const std::int32_t> node_rank, int rank);

// blocks: the degree blocks of the elements (every element in one); element_vessel: per
// element its vessel; vessel_rank: per vessel its rank (a 0D vessel's not read).
OneDCut one_d_cut(const NetworkBoundaries& ends, std::span<const ElementRun> blocks,
                  std::span<const std::int32_t> element_vessel, std::span<const std::int32_t> vessel_rank, int rank);

}  // namespace hemotree
