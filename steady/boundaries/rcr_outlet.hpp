// An RCR outlet's steady row (pulse/boundaries/rcr_outlet.hpp is its pulsatile form): in a
// steady flow the capacitor carries nothing, so R1 and R2 are in series, a shunt
// 1/(R1 + R2) to p_out.
#pragma once

#include <cstddef>

#include "steady/boundaries/nodal_rows.hpp"
#include "steady/boundaries/resistance_outlet.hpp"

namespace hemotree::steady {

struct RcrOutlet {
  double r1 = 0, r2 = 0;  // [Pa s/m^3]
  double p_out = 0;       // [Pa]

  void add_row(NodalRows& rows, std::size_t node) const { ResistanceOutlet{r1 + r2, p_out}.add_row(rows, node); }
};

}  // namespace hemotree::steady
