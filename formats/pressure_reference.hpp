// A pressure to refer to, fixed at a node the user names, for a connected part that has flow
// boundaries only. Where those flows balance, the part's flows follow from them alone and its
// pressures are determined up to one level: the named node's pressure sets that level and
// the node then takes up nothing. Where they do not balance the part has no steady solution,
// and a pressure at the node would hide the difference as a flow out of it.
#pragma once

#include <cstdint>

#include "formats/connected_parts.hpp"
#include "formats/network.hpp"

namespace hemotree {

// Adds a constant pressure boundary [Pa] at the node of id node_id, having checked that the
// node exists and some vessel meets it, that it has no boundary condition yet, that the
// pressure lies in the format's range, that its part has no pressure or outlet to refer to,
// and that the part's flow boundaries balance (mean flows of waveforms that vary in time,
// within flow_balance_tolerance of the largest). InputError otherwise, one line naming the
// node, the part and, for flows that do not balance, their net inflow in ml/min. Returns the
// part it now refers (its flow balance, for a note: flow_balance(part)).
ConnectedPart fix_pressure_at(Network& net, std::int64_t node_id, double pressure);

}  // namespace hemotree
