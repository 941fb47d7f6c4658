// A prescribed pressure's steady row (pulse/boundaries/pressure_end.hpp is its pulsatile
// form): its node's pressure is its period mean, p_i = P, eliminated from the system.
#pragma once

#include <cstddef>

#include "steady/boundaries/nodal_rows.hpp"

namespace hemotree::steady {

struct PressureEnd {
  double pressure = 0;  // mean p [Pa]

  void add_row(NodalRows& rows, std::size_t node) const {
    rows.prescribed[node] = 1;
    rows.pressure[node] = pressure;
  }
};

}  // namespace hemotree::steady
