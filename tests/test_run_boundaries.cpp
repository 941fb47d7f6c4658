// The run's boundary list (formats/run_boundaries): a view of the network that must read as
// the list it replaced, the tree form's outlets, its inlet, then the node boundaries, each
// made as as_node_boundary makes it; and its parts, asked for alone, the same as the whole.
#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "formats/run_boundaries.hpp"
#include "tests/network_builders.hpp"

using namespace hemotree;
using test_networks::rcr_outlet;
using test_networks::resistance_outlet;

namespace {

Waveform table_flow() {
  Waveform w;
  w.shape = Waveform::Shape::table;
  w.period = 0.8;
  w.time = {0.0, 0.4};
  w.value = {1e-6, 3e-6};
  return w;
}

void expect_same(const NodeBoundary& got, const NodeBoundary& want, std::size_t i) {
  EXPECT_EQ(got.node, want.node) << i;
  EXPECT_EQ(got.type, want.type) << i;
  EXPECT_EQ(got.outlet.vessel, want.outlet.vessel) << i;
  EXPECT_EQ(got.outlet.type, want.outlet.type) << i;
  EXPECT_EQ(got.outlet.r, want.outlet.r) << i;
  EXPECT_EQ(got.outlet.r1, want.outlet.r1) << i;
  EXPECT_EQ(got.outlet.c, want.outlet.c) << i;
  EXPECT_EQ(got.outlet.r2, want.outlet.r2) << i;
  EXPECT_EQ(got.outlet.p_out, want.outlet.p_out) << i;
  EXPECT_EQ(got.waveform.shape, want.waveform.shape) << i;
  EXPECT_EQ(got.waveform.period, want.waveform.period) << i;
  EXPECT_EQ(got.waveform.mean, want.waveform.mean) << i;
  EXPECT_EQ(got.waveform.time, want.waveform.time) << i;
  EXPECT_EQ(got.waveform.value, want.waveform.value) << i;
  EXPECT_EQ(got.hematocrit == got.hematocrit, want.hematocrit == want.hematocrit) << i;
}

// Every part read alone equals the same part of the whole boundary.
void expect_parts_agree(const RunBoundaries& list) {
  for (std::size_t i = 0; i < list.size(); ++i) {
    const NodeBoundary whole = list[i];
    EXPECT_EQ(list.node(i), whole.node) << i;
    EXPECT_EQ(list.type(i), whole.type) << i;
    EXPECT_EQ(list.is_outlet(i), whole.is_outlet()) << i;
    EXPECT_EQ(list.outlet(i).r, whole.outlet.r) << i;
    EXPECT_EQ(list.outlet(i).r1, whole.outlet.r1) << i;
    EXPECT_EQ(list.waveform(i).mean, whole.waveform.mean) << i;
    EXPECT_EQ(list.waveform(i).value, whole.waveform.value) << i;
  }
}

}  // namespace

// The tree form: its outlets in net.outlets' order (at their vessels' `to` nodes, each with
// its vessel), then its inlet (a flow into its vessel's `from` node, with its waveform).
TEST(RunBoundaries, TheTreeFormsOutletsThenItsInlet) {
  Network net = test_networks::bifurcation(10);  // node ids 10 to 13
  net.outlets = {rcr_outlet(2, 1e8, 1e-11, 7e8, 500), resistance_outlet(1, 6e8, 1333)};
  net.inlet = Inlet{0, table_flow()};
  const RunBoundaries list(net);
  ASSERT_EQ(list.size(), 3u);
  expect_same(list[0], as_node_boundary(net, net.outlets[0]), 0);
  expect_same(list[1], as_node_boundary(net, net.outlets[1]), 1);
  expect_same(list[2], as_node_boundary(net, *net.inlet), 2);
  EXPECT_EQ(list.node(0), 3);  // vessel 2's `to`
  EXPECT_EQ(list.node(1), 2);
  EXPECT_EQ(list.node(2), 0);  // vessel 0's `from`
  EXPECT_EQ(list.outlet(0).vessel, 2);
  expect_parts_agree(list);
  std::size_t count = 0;
  for (const NodeBoundary& b : list) expect_same(b, list[count], count), ++count;
  EXPECT_EQ(count, list.size());
}

// The node form: net.boundaries as they are, in their order.
TEST(RunBoundaries, TheNodeFormsBoundariesInTheirOrder) {
  Network net = test_networks::bifurcation(10);  // node ids 10 to 13
  NodeBoundary in, out, held;
  in.node = 0, in.type = BoundaryType::flow, in.waveform = table_flow();
  out.node = 3, out.type = BoundaryType::resistance, out.outlet.type = BoundaryType::resistance, out.outlet.r = 5e8;
  held.node = 2, held.type = BoundaryType::pressure, held.waveform = Waveform::constant_value(1333);
  net.boundaries = {out, in, held};
  const RunBoundaries list(net);
  ASSERT_EQ(list.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) expect_same(list[i], net.boundaries[i], i);
  expect_parts_agree(list);
}

// Two conditions at one node are refused, naming the node, as node_boundaries refuses them.
TEST(RunBoundaries, RefusesTwoConditionsAtOneNode) {
  Network net = test_networks::bifurcation(10);  // node ids 10 to 13
  net.outlets = {resistance_outlet(1, 6e8, 1333), resistance_outlet(2, 6e8, 1333)};
  NodeBoundary extra;
  extra.node = 2, extra.type = BoundaryType::pressure, extra.waveform = Waveform::constant_value(1000);
  net.boundaries = {extra};
  try {
    const RunBoundaries list(net);
    FAIL() << "accepted two conditions at node 12";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("node 12"), std::string::npos) << e.what();
  }
}
