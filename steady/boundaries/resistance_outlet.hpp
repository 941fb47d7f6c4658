// A resistance outlet's steady row (pulse/boundaries/resistance_outlet.hpp is its pulsatile
// form): a shunt 1/R from its node to p_out, Q = (p_i - p_out) / R, so G_i += 1/R and
// b_i += p_out / R.
#pragma once

#include <cstddef>

#include "steady/boundaries/nodal_rows.hpp"

namespace hemotree::steady {

struct ResistanceOutlet {
  double resistance = 0;  // R [Pa s/m^3]
  double p_out = 0;       // [Pa]

  void add_row(NodalRows& rows, std::size_t node) const {
    rows.shunt[node] += 1 / resistance;
    rows.inflow[node] += p_out / resistance;
  }
};

}  // namespace hemotree::steady
