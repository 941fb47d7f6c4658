// A prescribed flow's steady row (pulse/boundaries/flow_inlet.hpp is its pulsatile form): its
// period mean Q_in injected at its node, b_i += Q_in.
#pragma once

#include <cstddef>

#include "steady/boundaries/nodal_rows.hpp"

namespace hemotree::steady {

struct FlowInlet {
  double inflow = 0;  // mean Q_in [m^3/s], into the network

  void add_row(NodalRows& rows, std::size_t node) const { rows.inflow[node] += inflow; }
};

}  // namespace hemotree::steady
