// A grown arterial tree and its venous mirror: each arterial vessel a -> b gets a venous twin
// b' -> a' that carries its flow back, the terminal vessels' distal nodes shared by both
// trees, so every capillary bed closes an arterio-venous loop (terminals - 1 independent loops
// in all). The paper replaces the veins by boundary conditions; with them the network has one
// inflow (the arterial root) and one outflow (the venous root) and loops everywhere: the
// largest measured-like network to test the network-flow solvers on.
#pragma once

#include "formats/network.hpp"

namespace hemotree {

struct VenousMirror {
  double diameter_ratio = 1;   // venous twin's diameter / its artery's (an exact mirror by default)
  double mean_flow = 0;        // into the arterial root [m^3/s]: a flow boundary there
  double venous_pressure = 0;  // at the venous root [Pa]: a pressure boundary there
  double offset = 0;           // the venous nodes sit this far below the arterial ones in z [m]
};

// Appends the twins (ids after the arteries', in reverse order, so the venous root comes
// last), their nodes, and the two boundaries; generations count on from the capillaries.
// Expects a rooted tree (check_rooted_tree); keeps the arterial vessels' and nodes' indices.
void add_venous_mirror(Network& net, const VenousMirror& mirror);

}  // namespace hemotree
