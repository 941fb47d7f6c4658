// A pseudo-3D layout of a tree, so that it reads as a tree in ParaView: each vessel runs
// straight for its length; daughters leave their parent at Murray's minimum-work branching
// angles, and each bifurcation plane is turned 90 degrees from its parent's, as in
// space-filling arterial trees. Only the picture depends on it; no result does.
#pragma once

#include "formats/network.hpp"

namespace hemotree {

// Sets the coordinates of every node; InputError if the network is not a rooted tree.
void lay_out_tree(Network& net);

// Murray's optimal branching angle of daughter 1 from the parent's axis (Murray 1926,
// Zamir 1978): cos(theta1) = (D0^4 + D1^4 - D2^4) / (2 D0^2 D1^2), clamped to [0, 90 deg].
double murray_branching_angle(double parent, double daughter, double sibling);

}  // namespace hemotree
