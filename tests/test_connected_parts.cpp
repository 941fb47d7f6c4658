// Connected parts of a network (formats/connected_parts.hpp), the largest of them alone
// (formats/largest_part.hpp) and a pressure fixed at a node of a flows-only part
// (formats/pressure_reference.hpp), on a small fragmented network worked out by hand.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "formats/connected_parts.hpp"
#include "formats/largest_part.hpp"
#include "formats/network_io.hpp"
#include "formats/pressure_reference.hpp"
#include "tests/network_builders.hpp"
#include "tests/scratch_path.hpp"

using namespace hemotree;
using test_networks::flow_boundary;
using test_networks::pressure_boundary;

namespace {

// Three parts and a node no vessel meets, their vessels interleaved in the arrays:
//   A: nodes 100-104, vessels 7 (100->101), 3 (101->102), 9 (102->103), 5 (103->101), 8 (103->104):
//      a loop with a tail, 0.5 ul/s in at node 100 and 20 mmHg at node 104;
//   C: nodes 200-202, vessels 40, 41: flows 1e-9 in and 1e-9 out, balanced;
//   B: nodes 300-302, vessels 50, 51: 1e-9 in, nothing out;
//   node 999 alone.
// Every vessel carries every optional field; vessel 9 tapers.
Network fragmented() {
  Network net;
  const std::int64_t ids[] = {100, 200, 101, 300, 102, 999, 103, 201, 104, 301, 202, 302};
  for (std::size_t k = 0; k < std::size(ids); ++k)
    net.add_node(ids[k], 1e-3 * static_cast<double>(k), 2e-3, -1e-3 * static_cast<double>(ids[k]) / 100);
  auto node = [&](std::int64_t id) {
    for (std::size_t i = 0; i < net.node_count(); ++i)
      if (net.node_id[i] == id) return static_cast<std::int32_t>(i);
    return std::int32_t{-1};
  };
  struct Vessel {
    std::int64_t id, from, to;
  };
  const Vessel vessels[] = {{50, 300, 301}, {7, 100, 101}, {40, 200, 201}, {3, 101, 102}, {9, 102, 103},
                            {51, 301, 302}, {5, 103, 101}, {41, 201, 202}, {8, 103, 104}};
  for (const Vessel& v : vessels)
    net.add_vessel(v.id, node(v.from), node(v.to), 1e-3 * static_cast<double>(v.id), 1e-4 + 1e-6 * static_cast<double>(v.id),
                   1e-5, 1e6, static_cast<std::int32_t>(v.id % 3));
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    net.beta.push_back(1e6 + static_cast<double>(net.id[v]));
    net.reference_pressure.push_back(1000 + static_cast<double>(net.id[v]));
    net.distal_diameter.push_back(net.id[v] == 9 ? 5e-5 : std::nan(""));
  }
  net.boundaries = {flow_boundary(node(100), 0.5e-9), flow_boundary(node(200), 1e-9), flow_boundary(node(300), 1e-9),
                    pressure_boundary(node(104), 2666.4), flow_boundary(node(202), -1e-9)};
  std::sort(net.boundaries.begin(), net.boundaries.end(),
            [](const NodeBoundary& a, const NodeBoundary& b) { return a.node < b.node; });
  net.blood = test_networks::newtonian(3.5e-3);
  net.provenance = {{"tool", "test"}};
  net.extra = {{"unknown_member", 1}};
  return net;
}

std::int32_t node_of(const Network& net, std::int64_t id) {
  for (std::size_t i = 0; i < net.node_count(); ++i)
    if (net.node_id[i] == id) return static_cast<std::int32_t>(i);
  return -1;
}

std::vector<std::int64_t> boundary_ids(const Network& net, const ConnectedPart& part) {
  std::vector<std::int64_t> ids;
  for (const std::int32_t i : part.boundary_nodes) ids.push_back(net.node_id[static_cast<std::size_t>(i)]);
  return ids;
}

void expect_refusal(Network net, std::int64_t node, double pressure, const std::string& fragment) {
  try {
    fix_pressure_at(net, node, pressure);
    ADD_FAILURE() << "no refusal, expected: " << fragment;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << "one line";
  }
}

}  // namespace

TEST(ConnectedParts, LargestFirstWithTheirBoundaries) {
  const Network net = fragmented();
  const ConnectedParts parts = connected_parts(net);
  ASSERT_EQ(parts.parts.size(), 3u);
  const ConnectedPart &a = parts.parts[0], &c = parts.parts[1], &b = parts.parts[2];
  EXPECT_EQ(a.lowest_vessel_id, 3);
  EXPECT_EQ(a.vessels, 5u);
  EXPECT_EQ(a.nodes, 5u);
  EXPECT_EQ(boundary_ids(net, a), (std::vector<std::int64_t>{100, 104}));
  EXPECT_TRUE(a.pressure_reference);
  EXPECT_DOUBLE_EQ(a.net_inflow, 0.5e-9);  // the pressure node's flow is no boundary flow
  // Of the two parts of two vessels, the one with the lower vessel id comes first.
  EXPECT_EQ(c.lowest_vessel_id, 40);
  EXPECT_EQ(b.lowest_vessel_id, 50);
  EXPECT_EQ(c.nodes, 3u);
  EXPECT_FALSE(c.pressure_reference);
  EXPECT_TRUE(c.flows_balance());
  EXPECT_FALSE(b.flows_balance());
  EXPECT_DOUBLE_EQ(b.net_inflow, 1e-9);
  EXPECT_DOUBLE_EQ(b.largest_flow, 1e-9);
  EXPECT_FALSE(b.time_varying_flows);
  EXPECT_EQ(parts.part_of_node[static_cast<std::size_t>(node_of(net, 999))], -1);
  EXPECT_EQ(parts.part_of_node[static_cast<std::size_t>(node_of(net, 103))], 0);
  EXPECT_EQ(parts.part_of_node[static_cast<std::size_t>(node_of(net, 201))], 1);
  EXPECT_EQ(parts.part_of_node[static_cast<std::size_t>(node_of(net, 302))], 2);
  // The union-find agrees: the same root within a part, different ones across.
  NodeParts roots(net);
  EXPECT_EQ(roots.root(node_of(net, 100)), roots.root(node_of(net, 104)));
  EXPECT_NE(roots.root(node_of(net, 100)), roots.root(node_of(net, 200)));
}

TEST(ConnectedParts, MessagesNameThePartItsNodesAndItsBalance) {
  Network net = fragmented();
  ConnectedParts parts = connected_parts(net);
  EXPECT_EQ(part_name(parts.parts[0]), "the part with vessel 3 (5 vessels)");
  EXPECT_EQ(boundary_node_list(net, parts.parts[0]), "100, 104");
  EXPECT_EQ(flow_balance(parts.parts[1]), "the flows balance");
  EXPECT_EQ(flow_balance(parts.parts[2]), "the net inflow is 0.06 ml/min");
  // Seven boundary nodes on a star: five named, then how many more; a waveform is compared by
  // its mean.
  Network star;
  star.add_node(0);
  for (int k = 1; k <= 7; ++k) {
    star.add_node(10 * k);
    star.add_vessel(k, 0, k, 1e-3, 1e-4, 1e-5, 1e6, 0);
    Waveform w;  // half sine of mean 1e-9
    w.mean = k < 7 ? 1e-9 : -6e-9;
    star.boundaries.push_back(flow_boundary(k, w));
  }
  const ConnectedPart one = connected_parts(star).parts[0];
  EXPECT_EQ(part_name(one), "the part with vessel 1 (7 vessels)");
  EXPECT_EQ(boundary_node_list(star, one), "10, 20, 30, 40, 50 and 2 more");
  EXPECT_EQ(boundary_node_list(star, one, 7), "10, 20, 30, 40, 50, 60, 70");
  EXPECT_TRUE(one.time_varying_flows);
  EXPECT_EQ(flow_balance(one), "the mean flows balance");
}

TEST(LargestPart, KeepsEveryFieldAndIdOfTheLargestPart) {
  const Network net = fragmented();
  DroppedParts dropped;
  const Network part = largest_connected_part(net, &dropped);
  EXPECT_EQ(part.id, (std::vector<std::int64_t>{7, 3, 9, 5, 8}));  // their order in the file
  EXPECT_EQ(part.node_id, (std::vector<std::int64_t>{100, 101, 102, 103, 104}));
  ASSERT_EQ(part.x.size(), 5u);
  for (std::size_t v = 0; v < part.vessel_count(); ++v) {
    const auto w = static_cast<std::size_t>(net.index_of(part.id[v]));
    EXPECT_EQ(part.node_id[static_cast<std::size_t>(part.from[v])], net.node_id[static_cast<std::size_t>(net.from[w])]);
    EXPECT_EQ(part.node_id[static_cast<std::size_t>(part.to[v])], net.node_id[static_cast<std::size_t>(net.to[w])]);
    EXPECT_EQ(part.length[v], net.length[w]);
    EXPECT_EQ(part.diameter[v], net.diameter[w]);
    EXPECT_EQ(part.wall_thickness[v], net.wall_thickness[w]);
    EXPECT_EQ(part.youngs_modulus[v], net.youngs_modulus[w]);
    EXPECT_EQ(part.generation[v], net.generation[w]);
    EXPECT_EQ(part.vessel_class[v], net.vessel_class[w]);
    EXPECT_EQ(part.beta[v], net.beta[w]);
    EXPECT_EQ(part.reference_pressure[v], net.reference_pressure[w]);
    EXPECT_EQ(part.is_tapered(v), part.id[v] == 9);
  }
  for (std::size_t i = 0; i < part.node_count(); ++i) {
    const auto j = static_cast<std::size_t>(node_of(net, part.node_id[i]));
    EXPECT_EQ(part.x[i], net.x[j]);
    EXPECT_EQ(part.y[i], net.y[j]);
    EXPECT_EQ(part.z[i], net.z[j]);
  }
  ASSERT_EQ(part.boundaries.size(), 2u);
  EXPECT_EQ(part.node_id[static_cast<std::size_t>(part.boundaries[0].node)], 100);
  EXPECT_EQ(part.boundaries[0].type, BoundaryType::flow);
  EXPECT_EQ(part.node_id[static_cast<std::size_t>(part.boundaries[1].node)], 104);
  EXPECT_EQ(part.boundaries[1].waveform.mean_value(), 2666.4);
  EXPECT_EQ(part.blood->newtonian_viscosity, 3.5e-3);
  EXPECT_EQ(part.provenance, net.provenance);
  EXPECT_EQ(part.extra, net.extra);
  EXPECT_EQ(dropped.parts, 2u);
  EXPECT_EQ(dropped.vessels, 4u);
  EXPECT_EQ(dropped.nodes, 7u);  // 6 in parts, and node 999
  EXPECT_EQ(dropped.boundary_nodes, 3u);
  EXPECT_FALSE(dropped.generations_recounted);
  EXPECT_EQ(describe(part, dropped), "kept the largest connected part, 5 vessels and 5 nodes; dropped 2 parts: "
                                     "4 vessels, 7 nodes, 3 boundary nodes");
  // What it keeps is a valid file that reads back the same.
  const std::filesystem::path path = scratch_path("largest-part.json");
  {
    OutputStream out(path.string());
    write_network(part, out);
    out.commit();
  }
  const Network again = read_network(path.string());
  std::filesystem::remove(path);
  EXPECT_EQ(again.id, part.id);
  EXPECT_EQ(again.from, part.from);
  EXPECT_EQ(again.boundaries.size(), 2u);
}

// The tree form: the inlet and the outlets on kept vessels stay (outlets re-indexed); those on
// dropped vessels go. Generations counted over more vessels than the part keeps are counted
// again, so that the file stays within the format's bound.
TEST(LargestPart, TreeFormAndGenerationsBeyondTheKeptCount) {
  Network net;
  for (int k = 0; k < 6; ++k) net.add_node(k);
  net.add_vessel(10, 3, 4, 1e-3, 1e-4, 1e-5, 1e6, 4);  // a fragment, with an outlet
  net.add_vessel(11, 0, 1, 1e-3, 1e-4, 1e-5, 1e6, 5);
  net.add_vessel(12, 1, 2, 1e-3, 1e-4, 1e-5, 1e6, 6);
  net.add_vessel(13, 1, 5, 1e-3, 1e-4, 1e-5, 1e6, 6);
  net.inlet = Inlet{11, Waveform::constant_value(1e-9)};
  net.outlets = {test_networks::resistance_outlet(0, 1e9, 0), test_networks::resistance_outlet(2, 2e9, 0),
                 test_networks::resistance_outlet(3, 3e9, 0)};
  DroppedParts dropped;
  const Network part = largest_connected_part(net, &dropped);
  ASSERT_TRUE(part.inlet.has_value());
  EXPECT_EQ(part.inlet->vessel, 11);
  ASSERT_EQ(part.outlets.size(), 2u);
  EXPECT_EQ(part.outlets[0].vessel, 1);  // vessel 12
  EXPECT_EQ(part.outlets[0].r, 2e9);
  EXPECT_EQ(part.outlets[1].vessel, 2);  // vessel 13
  EXPECT_EQ(dropped.boundary_nodes, 1u);
  EXPECT_TRUE(dropped.generations_recounted);
  EXPECT_EQ(part.generation, (std::vector<std::int32_t>{0, 1, 1}));
  // The inlet goes with its vessel when another part is larger.
  net.inlet->vessel = 10;
  EXPECT_FALSE(largest_connected_part(net).inlet.has_value());
  EXPECT_THROW(largest_connected_part(Network{}), InputError);
}

TEST(LargestPart, OfEqualPartsTheOneWithTheLowestVesselId) {
  Network net;
  for (int k = 0; k < 4; ++k) net.add_node(k);
  net.add_vessel(8, 0, 1, 1e-3, 1e-4, 1e-5, 1e6, 0);
  net.add_vessel(6, 2, 3, 1e-3, 1e-4, 1e-5, 1e6, 0);
  DroppedParts dropped;
  const Network part = largest_connected_part(net, &dropped);
  EXPECT_EQ(part.id, (std::vector<std::int64_t>{6}));
  EXPECT_EQ(part.node_id, (std::vector<std::int64_t>{2, 3}));
  EXPECT_EQ(dropped.parts, 1u);
  // A network of one part loses nothing.
  DroppedParts none;
  const Network whole = largest_connected_part(part, &none);
  EXPECT_EQ(whole.id, part.id);
  EXPECT_EQ(none.parts, 0u);
  EXPECT_EQ(none.vessels, 0u);
  EXPECT_EQ(describe(whole, none), "kept the largest connected part, 1 vessel and 2 nodes; the network is one part: "
                                   "nothing dropped");
}

TEST(PressureReference, FixesThePressureOfABalancedFlowsOnlyPart) {
  Network net = fragmented();
  const ConnectedPart part = fix_pressure_at(net, 201, 1333.2);
  EXPECT_EQ(part.lowest_vessel_id, 40);
  EXPECT_TRUE(part.pressure_reference);
  EXPECT_EQ(boundary_ids(net, part), (std::vector<std::int64_t>{200, 201, 202}));
  ASSERT_EQ(net.boundaries.size(), 6u);
  for (std::size_t k = 1; k < net.boundaries.size(); ++k) EXPECT_LT(net.boundaries[k - 1].node, net.boundaries[k].node);
  const auto fixed = std::find_if(net.boundaries.begin(), net.boundaries.end(),
                                  [&](const NodeBoundary& b) { return b.node == node_of(net, 201); });
  ASSERT_NE(fixed, net.boundaries.end());
  EXPECT_EQ(fixed->type, BoundaryType::pressure);
  EXPECT_EQ(fixed->waveform.mean_value(), 1333.2);
  EXPECT_TRUE(connected_parts(net).parts[1].pressure_reference);
}

TEST(PressureReference, RefusesWhatWouldNotDetermineTheFlow) {
  const Network net = fragmented();
  const std::string at = "cannot fix a pressure at node ";
  expect_refusal(net, 77, 0, at + "77: the network has no node of that id");
  expect_refusal(net, 201, 2e5, at + "201: \"pressure\" must lie in [-1e5, 1e5] Pa (got 2e5)");
  expect_refusal(net, 200, 0, at + "200: it has a flow boundary already");
  expect_refusal(net, 999, 0, at + "999: no vessel meets it");
  expect_refusal(net, 102, 0, at + "102: the part with vessel 3 (5 vessels) has a pressure to refer to already (at node 104)");
  expect_refusal(net, 301, 0,
                 at + "301: the flows into the part with vessel 50 (2 vessels) do not balance: their sum is 0.06 ml/min "
                      "against 0.06 ml/min at most through one node, and a pressure would take up the difference");
  // Waveforms that vary in time are compared by their mean flows, and the refusal says so.
  Network pulsing = net;
  for (NodeBoundary& b : pulsing.boundaries)
    if (pulsing.node_id[static_cast<std::size_t>(b.node)] == 200) {
      Waveform w;  // half sine
      w.mean = 1.5e-9;
      b.waveform = w;
    }
  expect_refusal(pulsing, 201, 0,
                 at + "201: the mean flows into the part with vessel 40 (2 vessels) do not balance: their sum is 0.03 "
                      "ml/min against 0.09 ml/min at most through one node (waveforms compared by their mean flows)");
  // Within the tolerance of the largest mean flow they balance.
  for (NodeBoundary& b : pulsing.boundaries)
    if (pulsing.node_id[static_cast<std::size_t>(b.node)] == 200) b.waveform.mean = 1e-9 * (1 + 1e-10);
  const ConnectedPart part = fix_pressure_at(pulsing, 201, 0);
  EXPECT_TRUE(part.time_varying_flows);
  EXPECT_EQ(flow_balance(part), "the mean flows balance");
}
