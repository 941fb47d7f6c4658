// The loaded resistive tree (steady/loaded_tree) against hand calculations: the potentials of
// injected currents and shunts, through vessels, R outlets and RCR outlets' capacitor nodes.
#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "steady/loaded_tree.hpp"
#include "tests/network_builders.hpp"

using namespace hemotree;
using test_networks::bifurcation;
using test_networks::rcr_outlet;
using test_networks::resistance_outlet;

namespace {

// The network: test_networks::bifurcation(), with vessel resistances 1, 2, 4 below.

TreeLoads no_loads(const Network& net) {
  TreeLoads l;
  l.node_shunt.assign(net.node_count(), 0.0);
  l.node_current.assign(net.node_count(), 0.0);
  l.capacitor_shunt.assign(net.outlets.size(), 0.0);
  l.capacitor_current.assign(net.outlets.size(), 0.0);
  return l;
}

const std::vector<double> resistance = {1, 2, 4};

}  // namespace

// A current I into the junction (node 1) leaves through both daughters and their outlets
// (R 3 and 6): 2 + 3 = 5 in parallel with 4 + 6 = 10 is 10/3, so node 1 sits at 10 I / 3;
// the open inlet carries nothing, so node 0 sits there too; the branch current 10 I / 15
// flows through R 3 to node 2's outlet.
TEST(LoadedTree, ACurrentIntoTheJunctionDividesByConductance) {
  Network net = bifurcation();
  net.outlets = {resistance_outlet(1, 3, 1333), resistance_outlet(2, 6, 1333)};
  TreeLoads loads = no_loads(net);
  loads.node_current[1] = 1.5;
  const TreePotentials p = solve_loaded_tree(net, resistance, loads);
  const double v1 = 1.5 * 10.0 / 3;
  EXPECT_NEAR(p.node[1], v1, 1e-12);
  EXPECT_NEAR(p.node[0], v1, 1e-12);
  EXPECT_NEAR(p.node[2], 3 * v1 / 5, 1e-12);
  EXPECT_NEAR(p.node[3], 6 * v1 / 10, 1e-12);
  // A shunt at node 1 takes its share: V = I / (g + 3/10).
  loads.node_shunt[1] = 0.2;
  EXPECT_NEAR(solve_loaded_tree(net, resistance, loads).node[1], 1.5 / (0.2 + 0.3), 1e-12);
}

// An RCR outlet: a current into its capacitor node sees R2 (= 7) in parallel with R1 (= 1)
// and the rest of the tree to ground (vessel 1 back to the junction, then the other branch:
// 2 + (4 + 6) = 12), so 1 / (1/7 + 1/13); the junction is the divider's share of it.
TEST(LoadedTree, ACapacitorNodeOfAnRcrOutlet) {
  Network net = bifurcation();
  net.outlets = {rcr_outlet(1, 1, 1e-9, 7, 0), resistance_outlet(2, 6, 1333)};
  TreeLoads loads = no_loads(net);
  loads.capacitor_current[0] = 2.0;
  const TreePotentials p = solve_loaded_tree(net, resistance, loads);
  const double vc = 2.0 / (1.0 / 7 + 1.0 / 13);
  EXPECT_NEAR(p.capacitor[0], vc, 1e-12);
  EXPECT_NEAR(p.node[2], vc * 12 / 13, 1e-12);
  EXPECT_NEAR(p.node[1], vc * 10 / 13, 1e-12);
  EXPECT_NEAR(p.node[3], vc * 6 / 13, 1e-12);
  EXPECT_EQ(p.capacitor[1], 0.0);  // an R outlet has no capacitor node
  // Unloaded, everything is at the (zero) outflow pressure.
  for (const double v : solve_loaded_tree(net, resistance, no_loads(net)).node) EXPECT_EQ(v, 0.0);
}

// Without RCR outlets the capacitor loads may be left empty (a tree's two million capillary
// outlets): the same potentials, to the bit; with one, empty loads are refused.
TEST(LoadedTree, TakesNoCapacitorLoadsWithoutRcrOutlets) {
  Network net = bifurcation();
  net.outlets = {resistance_outlet(1, 3, 1333), resistance_outlet(2, 6, 1333)};
  TreeLoads full = no_loads(net);
  full.node_current[1] = 1.5;
  full.node_shunt[2] = 0.1;
  TreeLoads empty = full;
  empty.capacitor_shunt.clear();
  empty.capacitor_current.clear();
  EXPECT_EQ(solve_loaded_tree(net, resistance, empty).node, solve_loaded_tree(net, resistance, full).node);
  net.outlets[0] = rcr_outlet(1, 1, 1e-9, 7, 0);
  EXPECT_THROW(solve_loaded_tree(net, resistance, empty), std::invalid_argument);
}

TEST(LoadedTree, RefusesATerminalVesselWithoutAnOutlet) {
  Network net = bifurcation();
  net.outlets = {resistance_outlet(1, 3, 1333)};
  EXPECT_THROW(solve_loaded_tree(net, resistance, no_loads(net)), InputError);
}

// One tree for several loads (the compliance balance's three solves): each solve is the
// single call's, bit for bit, whatever came before it; and the loads' sizes are checked.
TEST(LoadedTree, SolvesAgainWithOtherLoadsAsTheSingleCallDoes) {
  Network net = bifurcation();
  net.outlets = {rcr_outlet(1, 1, 1e-9, 7, 0), resistance_outlet(2, 6, 1333)};
  const RunBoundaries boundaries(net);
  LoadedTree tree(net, boundaries, resistance);
  TreeLoads first = no_loads(net), second = no_loads(net);
  first.capacitor_current[0] = 2.0;
  second.node_shunt = {0.3, 0.1, 0.7, 0.05};
  second.node_current = {0.2, -1.0, 0.4, 3.0};
  second.capacitor_shunt[0] = 0.25;
  second.capacitor_current[0] = -0.5;
  for (const TreeLoads* loads : {&first, &second, &first}) {
    const TreePotentials once = solve_loaded_tree(net, resistance, *loads), again = tree.solve(*loads);
    EXPECT_EQ(again.node, once.node);
    EXPECT_EQ(again.capacitor, once.capacitor);
  }
  TreeLoads short_loads = no_loads(net);
  short_loads.node_current.pop_back();
  EXPECT_THROW(tree.solve(short_loads), std::invalid_argument);
}
