// Each vessel's tube law (physics/tube_law.hpp) from the network's data: given directly (beta
// and reference_pressure), or from its wall (diameter, thickness, Young's modulus) by the thin-
// or thick-walled model (physics/wall_law.hpp) against the external pressure. A tapered
// vessel's is its proximal end's (pulse/ builds the law along it, physics/vessel_taper.hpp).
// The steady distension, the linear periodic state and the pulsatile run all take these.
#pragma once

#include <vector>

#include "formats/network.hpp"
#include "physics/blood.hpp"
#include "physics/tube_law.hpp"

namespace hemotree {

// InputError naming the vessel where it has neither a beta nor a wall.
std::vector<TubeLaw> vessel_laws(const Network& net, const Blood& blood, double external_pressure,
                                 double thick_wall_ratio);

}  // namespace hemotree
