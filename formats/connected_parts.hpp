// The connected parts of a network: the pieces it falls into with its vessels taken as
// undirected edges. Networks from imaging come in several, most of them fragments; a flow
// problem needs a pressure to refer to in each (a pressure boundary or an outlet), and a part
// with flow boundaries only has a solution (up to its pressure level) only where they balance.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <span>
#include <string>
#include <vector>

#include "formats/network.hpp"
#include "formats/run_boundaries.hpp"

namespace hemotree {

// Union-find over node indices, keeping the lower root (short paths on a network numbered
// from its root): root(i) == root(j) when a path of vessels joins nodes i and j.
class NodeParts {
 public:
  explicit NodeParts(const Network& net) : up_(net.node_count()) {
    std::iota(up_.begin(), up_.end(), 0);
    for (std::size_t v = 0; v < net.vessel_count(); ++v) {
      const std::int32_t rf = root(net.from[v]), rt = root(net.to[v]);
      up_[static_cast<std::size_t>(std::max(rf, rt))] = std::min(rf, rt);
    }
  }
  std::int32_t root(std::int32_t i) {
    while (up_[static_cast<std::size_t>(i)] != i) {
      auto& next = up_[static_cast<std::size_t>(i)];
      next = up_[static_cast<std::size_t>(next)];  // path halving
      i = next;
    }
    return i;
  }

 private:
  std::vector<std::int32_t> up_;
};

// Flow boundaries balance when their mean flows sum to zero within this fraction of the
// largest: a part of flow boundaries only then has solutions, one for each pressure level.
inline constexpr double flow_balance_tolerance = 1e-9;

struct ConnectedPart {
  std::int64_t lowest_vessel_id = 0;  // names the part to the user
  std::size_t vessels = 0;
  std::size_t nodes = 0;
  std::vector<std::int32_t> boundary_nodes;  // node indices with a boundary condition, ascending
  bool pressure_reference = false;           // one of them a pressure or an outlet
  // The flow boundaries: the sum of their mean flows into the part, and the largest in
  // magnitude [m^3/s]; whether any of them varies in time (then these are its mean flow).
  double net_inflow = 0;
  double largest_flow = 0;
  bool time_varying_flows = false;

  bool flows_balance() const { return std::abs(net_inflow) <= flow_balance_tolerance * largest_flow; }
};

struct ConnectedParts {
  std::vector<ConnectedPart> parts;        // largest first: most vessels, then lowest vessel id
  std::vector<std::int32_t> part_of_node;  // index into parts; -1 for a node no vessel meets
};

// The parts of the network with its boundary conditions (node_boundaries(net) unless given);
// a boundary at a node no vessel meets belongs to no part. O(vessels + nodes + boundaries).
ConnectedParts connected_parts(const Network& net, std::span<const NodeBoundary> boundaries);
ConnectedParts connected_parts(const Network& net, const RunBoundaries& boundaries);
ConnectedParts connected_parts(const Network& net);

// Empty where every part has a pressure to refer to (a prescribed pressure or an outlet of any
// kind); else one line naming every part that has none, largest first, with its boundary
// nodes and the balance of its flows, and what would give it one (naming the setting
// pressure_at: core/setting_error.hpp). The steady solve and the pulsatile run refuse with it
// alike.
std::string pressure_reference_refusal(const Network& net, std::span<const NodeBoundary> boundaries);
std::string pressure_reference_refusal(const Network& net, const RunBoundaries& boundaries);

// "the part with vessel 12 (340 vessels)"
std::string part_name(const ConnectedPart& part);
// The boundary nodes by id, at most `shown` of them: "3, 7, 9, 11, 15 and 4 more".
std::string boundary_node_list(const Network& net, const ConnectedPart& part, std::size_t shown = 5);
// The flow boundaries' balance for a message: "the flows balance", "the mean flows balance"
// (waveforms compared by their means) or "the net mean inflow is 0.012 ml/min".
std::string flow_balance(const ConnectedPart& part);

}  // namespace hemotree
