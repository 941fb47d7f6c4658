// compute_stats, to_json and print_table on small networks whose statistics are worked out
// by hand.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli/setting_words.hpp"
#include "core/errors.hpp"
#include "stats/network_stats.hpp"

namespace hemotree {
namespace {

// Division, not multiplication by 1e-6: 10 / 1e6 is the double nearest 10 um, equal to the
// class bound 10e-6, whereas 10 * 1e-6 falls just below it and would classify as capillary.
constexpr double um(double x) { return x / 1e6; }
constexpr double mm(double x) { return x / 1e3; }
constexpr std::size_t artery = 0, small_artery = 1, arteriole = 2, capillary = 3;

// Adds a vessel with wall properties that statistics ignore.
void add(Network& net, std::int32_t from, std::int32_t to, double length, double diameter,
         int generation) {
  net.add_vessel(static_cast<std::int64_t>(net.vessel_count()) + 1, from, to, length, diameter,
                 0.1 * diameter, 1e6, generation);
}

// Network with nodes 0..count-1.
Network with_nodes(int count) {
  Network net;
  for (int i = 0; i < count; ++i) net.add_node(100 + i);
  return net;
}

double cylinder(double diameter, double length) {
  return std::numbers::pi / 4 * diameter * diameter * length;
}

// numpy.percentile's default, by full sort: the reference for the nth_element version.
double reference_percentile(std::vector<double> values, double p) {
  std::sort(values.begin(), values.end());
  const double h = static_cast<double>(values.size() - 1) * p;
  const auto k = static_cast<std::size_t>(std::floor(h));
  const double above = values[std::min(k + 1, values.size() - 1)];
  return values[k] + (h - static_cast<double>(k)) * (above - values[k]);
}

std::set<std::string> keys(const nlohmann::json& object) {
  std::set<std::string> out;
  for (const auto& item : object.items()) out.insert(item.key());
  return out;
}

TEST(NetworkStats, SingleVessel) {
  Network net = with_nodes(2);
  add(net, 0, 1, mm(20), um(3000), 0);
  const NetworkStats s = compute_stats(net);

  EXPECT_EQ(s.vessels, 1u);
  EXPECT_EQ(s.bifurcations, 0u);
  EXPECT_EQ(s.terminals, 1u);
  EXPECT_DOUBLE_EQ(s.total_length, mm(20));
  EXPECT_DOUBLE_EQ(s.total_volume, cylinder(um(3000), mm(20)));
  EXPECT_EQ(s.by_class[artery], 1u);
  ASSERT_EQ(s.generations.size(), 1u);
  const Quartiles& d = s.generations[0].diameter;
  for (double q : {d.min, d.q1, d.median, d.q3, d.max}) EXPECT_DOUBLE_EQ(q, um(3000));
  EXPECT_EQ(s.capillary_generation_min, -1);
  EXPECT_EQ(s.capillary_generation_max, -1);
}

TEST(NetworkStats, RootWithTwoDaughters) {
  Network net = with_nodes(4);
  add(net, 0, 1, mm(10), um(600), 0);
  add(net, 1, 2, mm(5), um(400), 1);
  add(net, 1, 3, mm(5), um(300), 1);
  const NetworkStats s = compute_stats(net);

  EXPECT_EQ(s.vessels, 3u);
  EXPECT_EQ(s.bifurcations, 1u);
  EXPECT_EQ(s.terminals, 2u);
  ASSERT_EQ(s.generations.size(), 2u);
  EXPECT_EQ(s.generations[0].vessels, 1u);
  EXPECT_EQ(s.generations[1].vessels, 2u);
  EXPECT_DOUBLE_EQ(s.generations[1].diameter.median, um(350));
}

// 0 -> 1 (artery), 1 -> 2, 3 (small artery, arteriole), then four arterioles of 10..40 um.
//
//   gen 0: 600 um, 10 mm         artery
//   gen 1: 200 um,  6 mm         small_artery
//           50 um,  4 mm         arteriole
//   gen 2: 40, 10, 30, 20 um, 1, 2, 3, 4 mm   arterioles (10 um is the lower bound)
TEST(NetworkStats, ThreeGenerationTree) {
  Network net = with_nodes(8);
  add(net, 0, 1, mm(10), um(600), 0);
  add(net, 1, 2, mm(6), um(200), 1);
  add(net, 1, 3, mm(4), um(50), 1);
  add(net, 2, 4, mm(1), um(40), 2);  // deliberately out of order
  add(net, 2, 5, mm(2), um(10), 2);
  add(net, 3, 6, mm(3), um(30), 2);
  add(net, 3, 7, mm(4), um(20), 2);
  const NetworkStats s = compute_stats(net);

  EXPECT_EQ(s.vessels, 7u);
  EXPECT_EQ(s.bifurcations, 3u);
  EXPECT_EQ(s.terminals, 4u);
  EXPECT_NEAR(s.total_length, mm(30), 1e-15);
  const double volume = cylinder(um(600), mm(10)) + cylinder(um(200), mm(6)) +
                        cylinder(um(50), mm(4)) + cylinder(um(40), mm(1)) +
                        cylinder(um(10), mm(2)) + cylinder(um(30), mm(3)) +
                        cylinder(um(20), mm(4));
  EXPECT_NEAR(s.total_volume, volume, 1e-12 * volume);

  EXPECT_EQ(s.by_class[artery], 1u);
  EXPECT_EQ(s.by_class[small_artery], 1u);
  EXPECT_EQ(s.by_class[arteriole], 5u);
  EXPECT_EQ(s.by_class[capillary], 0u);

  ASSERT_EQ(s.generations.size(), 3u);
  using Counts = std::array<std::size_t, vessel_class_count>;
  EXPECT_EQ(s.generations[0].by_class, (Counts{1, 0, 0, 0}));
  EXPECT_EQ(s.generations[1].by_class, (Counts{0, 1, 1, 0}));
  EXPECT_EQ(s.generations[2].by_class, (Counts{0, 0, 4, 0}));
  for (int g = 0; g < 3; ++g) EXPECT_EQ(s.generations[g].generation, g);

  // Two values: h = 0.25, 0.5, 0.75 between 50 and 200 um.
  const Quartiles& d1 = s.generations[1].diameter;
  EXPECT_DOUBLE_EQ(d1.min, um(50));
  EXPECT_DOUBLE_EQ(d1.q1, um(87.5));
  EXPECT_DOUBLE_EQ(d1.median, um(125));
  EXPECT_DOUBLE_EQ(d1.q3, um(162.5));
  EXPECT_DOUBLE_EQ(d1.max, um(200));

  // 10, 20, 30, 40 um: h = 0.75, 1.5, 2.25.
  const Quartiles& d2 = s.generations[2].diameter;
  EXPECT_DOUBLE_EQ(d2.min, um(10));
  EXPECT_DOUBLE_EQ(d2.q1, um(17.5));
  EXPECT_DOUBLE_EQ(d2.median, um(25));
  EXPECT_DOUBLE_EQ(d2.q3, um(32.5));
  EXPECT_DOUBLE_EQ(d2.max, um(40));
}

TEST(NetworkStats, OddCountQuartilesFallOnValues) {
  Network net = with_nodes(6);
  for (int i : {5, 1, 4, 2, 3}) add(net, 0, i, mm(1), um(i), 0);
  const Quartiles d = compute_stats(net).generations[0].diameter;
  EXPECT_DOUBLE_EQ(d.min, um(1));
  EXPECT_DOUBLE_EQ(d.q1, um(2));
  EXPECT_DOUBLE_EQ(d.median, um(3));
  EXPECT_DOUBLE_EQ(d.q3, um(4));
  EXPECT_DOUBLE_EQ(d.max, um(5));
}

// The partial ordering must give what a full sort gives, for any size and with ties.
TEST(NetworkStats, QuartilesMatchFullSort) {
  std::mt19937 rng(7);
  for (int size : {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 17, 100, 101, 1000, 4097}) {
    Network net = with_nodes(2);
    std::vector<double> diameters;
    // Few distinct values, so ties are common.
    std::uniform_int_distribution<int> pick(1, std::max(2, size / 3));
    for (int i = 0; i < size; ++i) diameters.push_back(um(pick(rng)));
    for (double d : diameters) add(net, 0, 1, mm(1), d, 3);

    const Quartiles d = compute_stats(net).generations[3].diameter;
    SCOPED_TRACE("size " + std::to_string(size));
    EXPECT_DOUBLE_EQ(d.min, reference_percentile(diameters, 0));
    EXPECT_DOUBLE_EQ(d.q1, reference_percentile(diameters, 0.25));
    EXPECT_DOUBLE_EQ(d.median, reference_percentile(diameters, 0.5));
    EXPECT_DOUBLE_EQ(d.q3, reference_percentile(diameters, 0.75));
    EXPECT_DOUBLE_EQ(d.max, reference_percentile(diameters, 1));
  }
}

TEST(NetworkStats, GapInGenerationsGivesZeroRow) {
  Network net = with_nodes(4);
  add(net, 0, 1, mm(1), um(200), 0);
  add(net, 1, 2, mm(1), um(5), 2);
  add(net, 1, 3, mm(1), um(7), 2);
  const NetworkStats s = compute_stats(net);

  ASSERT_EQ(s.generations.size(), 3u);
  const GenerationStats& empty = s.generations[1];
  EXPECT_EQ(empty.generation, 1);
  EXPECT_EQ(empty.vessels, 0u);
  EXPECT_EQ(empty.by_class, (std::array<std::size_t, vessel_class_count>{}));
  EXPECT_EQ(empty.diameter.min, 0);
  EXPECT_EQ(empty.diameter.median, 0);
  EXPECT_EQ(empty.diameter.max, 0);
  EXPECT_EQ(s.generations[2].vessels, 2u);
  EXPECT_DOUBLE_EQ(s.generations[2].diameter.median, um(6));

  // Generations that start beyond 0 still list 0 onwards.
  Network deep = with_nodes(2);
  add(deep, 0, 1, mm(1), um(50), 4);
  const NetworkStats t = compute_stats(deep);
  ASSERT_EQ(t.generations.size(), 5u);
  for (int g = 0; g < 4; ++g) EXPECT_EQ(t.generations[g].vessels, 0u);
  EXPECT_EQ(t.generations[4].vessels, 1u);
}

TEST(NetworkStats, TrifurcationCountsOnce) {
  Network net = with_nodes(5);
  add(net, 0, 1, mm(1), um(200), 0);
  add(net, 1, 2, mm(1), um(100), 1);
  add(net, 1, 3, mm(1), um(100), 1);
  add(net, 1, 4, mm(1), um(100), 1);
  const NetworkStats s = compute_stats(net);
  EXPECT_EQ(s.bifurcations, 1u);
  EXPECT_EQ(s.terminals, 3u);
}

// Where two vessels begin but none ends (two roots from one inlet node) is no bifurcation.
TEST(NetworkStats, BranchingWithoutParentIsNoBifurcation) {
  Network net = with_nodes(3);
  add(net, 0, 1, mm(1), um(200), 0);
  add(net, 0, 2, mm(1), um(200), 0);
  const NetworkStats s = compute_stats(net);
  EXPECT_EQ(s.bifurcations, 0u);
  EXPECT_EQ(s.terminals, 2u);
}

TEST(NetworkStats, CapillaryGenerationSpan) {
  Network net = with_nodes(6);
  add(net, 0, 1, mm(1), um(60), 0);
  add(net, 1, 2, mm(1), um(40), 1);
  add(net, 2, 3, mm(1), um(8), 2);   // capillary
  add(net, 2, 4, mm(1), um(20), 2);
  add(net, 4, 5, mm(1), um(9.9), 4);  // capillary, after an empty generation 3
  const NetworkStats s = compute_stats(net);
  EXPECT_EQ(s.by_class[capillary], 2u);
  EXPECT_EQ(s.capillary_generation_min, 2);
  EXPECT_EQ(s.capillary_generation_max, 4);

  const nlohmann::json j = to_json(s);
  EXPECT_EQ(j["capillary_generations"]["min"], 2);
  EXPECT_EQ(j["capillary_generations"]["max"], 4);
  EXPECT_EQ(j["capillary_generations"]["span"], 3);
}

TEST(NetworkStats, JsonKeysAndValues) {
  Network net = with_nodes(4);
  add(net, 0, 1, mm(10), um(600), 0);
  add(net, 1, 2, mm(5), um(40), 1);
  add(net, 1, 3, mm(5), um(20), 1);
  const nlohmann::json j = to_json(compute_stats(net));

  const std::set<std::string> classes = {"artery", "small_artery", "arteriole", "capillary"};
  EXPECT_EQ(keys(j), (std::set<std::string>{"vessels", "bifurcations", "terminals", "nodes_by_degree", "parts",
                                            "loops", "connected_parts", "boundary_nodes", "total_length",
                                            "total_volume", "classes", "capillary_generations", "generations"}));
  EXPECT_EQ(j["nodes_by_degree"], (nlohmann::json{{"1", 3}, {"3", 1}}));
  EXPECT_EQ(j["parts"], 1);
  ASSERT_EQ(j["connected_parts"].size(), 1u);
  EXPECT_EQ(keys(j["connected_parts"][0]), (std::set<std::string>{"lowest_vessel_id", "vessels", "nodes",
                                                                   "boundary_nodes", "pressure_reference",
                                                                   "flows_balance", "net_inflow"}));
  EXPECT_EQ(j["connected_parts"][0]["vessels"], 3);
  EXPECT_EQ(j["connected_parts"][0]["nodes"], 4);
  EXPECT_EQ(j["loops"], 0);
  EXPECT_EQ(j["boundary_nodes"]["flow"], 0);
  EXPECT_EQ(keys(j["classes"]), classes);
  EXPECT_TRUE(j["capillary_generations"].is_null());
  EXPECT_EQ(j["vessels"], 3);
  EXPECT_EQ(j["bifurcations"], 1);
  EXPECT_EQ(j["terminals"], 2);
  EXPECT_DOUBLE_EQ(j["total_length"].get<double>(), mm(20));
  EXPECT_EQ(j["classes"]["artery"], 1);
  EXPECT_EQ(j["classes"]["arteriole"], 2);

  ASSERT_TRUE(j["generations"].is_array());
  ASSERT_EQ(j["generations"].size(), 2u);
  const nlohmann::json& g1 = j["generations"][1];
  EXPECT_EQ(keys(g1), (std::set<std::string>{"generation", "vessels", "classes", "diameter"}));
  EXPECT_EQ(keys(g1["classes"]), classes);
  EXPECT_EQ(keys(g1["diameter"]), (std::set<std::string>{"min", "q1", "median", "q3", "max"}));
  EXPECT_EQ(g1["generation"], 1);
  EXPECT_EQ(g1["vessels"], 2);
  EXPECT_EQ(g1["classes"]["arteriole"], 2);
  EXPECT_DOUBLE_EQ(g1["diameter"]["median"].get<double>(), um(30));  // metres
  EXPECT_DOUBLE_EQ(g1["diameter"]["max"].get<double>(), um(40));
}

// A measured network: a loop written partly against its flow, a second part, boundaries at
// nodes. Loops are the cycle rank, vessels - nodes + parts, whatever the directions.
TEST(NetworkStats, LoopsPartsDegreesAndBoundaryNodes) {
  Network net = with_nodes(8);
  add(net, 0, 1, mm(1), um(20), 0);
  add(net, 2, 1, mm(1), um(20), 1);  // against the flow
  add(net, 1, 3, mm(1), um(20), 1);
  add(net, 3, 2, mm(1), um(20), 2);
  add(net, 2, 4, mm(1), um(20), 2);
  add(net, 4, 3, mm(1), um(20), 3);  // a second loop
  add(net, 5, 6, mm(1), um(20), 0);  // a part of its own, and node 7 alone (no vessel)
  NodeBoundary in, out;
  in.node = 0;
  in.type = BoundaryType::flow;
  out.node = 6;
  out.type = BoundaryType::pressure;
  net.boundaries = {in, out};
  const NetworkStats s = compute_stats(net);
  EXPECT_EQ(s.parts, 2u);
  EXPECT_EQ(s.loops, 2u);  // 7 vessels - 7 nodes touched + 2 parts
  EXPECT_EQ(s.nodes_by_degree, (std::vector<std::size_t>{0, 3, 1, 3}));  // ends 0, 5, 6; node 4 joins two
  EXPECT_EQ(s.boundaries_by_type[static_cast<std::size_t>(BoundaryType::flow)], 1u);
  EXPECT_EQ(s.boundaries_by_type[static_cast<std::size_t>(BoundaryType::pressure)], 1u);
  std::ostringstream table;
  print_table(s, table);
  EXPECT_NE(table.str().find("boundary nodes                    2  (1 flow, 1 pressure)"), std::string::npos) << table.str();
  // The parts, largest first, each named by its lowest vessel id.
  ASSERT_EQ(s.parts_by_size.size(), 2u);
  const PartStats& loop = s.parts_by_size[0];
  EXPECT_EQ(loop.lowest_vessel_id, 1);
  EXPECT_EQ(loop.vessels, 6u);
  EXPECT_EQ(loop.nodes, 5u);
  EXPECT_EQ(loop.boundary_nodes, 1u);
  EXPECT_FALSE(loop.pressure_reference);  // a flow in at node 0 only
  const PartStats& single = s.parts_by_size[1];
  EXPECT_EQ(single.lowest_vessel_id, 7);
  EXPECT_EQ(single.vessels, 1u);
  EXPECT_EQ(single.nodes, 2u);
  EXPECT_TRUE(single.pressure_reference);
  EXPECT_NE(table.str().find("  with vessel 1                 6          5               1  no (flows balance)\n"
                             "  with vessel 7                 1          2               1  yes\n"),
            std::string::npos)
      << table.str();
  const nlohmann::json j = to_json(s);
  EXPECT_EQ(j["connected_parts"][0]["lowest_vessel_id"], 1);
  EXPECT_EQ(j["connected_parts"][1]["pressure_reference"], true);
}

// Fragments of a measured network: equal parts ordered by their lowest vessel id, flows that
// do not balance reported in ml/min, and the table listing twenty parts, then what the rest hold.
TEST(NetworkStats, ConnectedPartsLargestFirst) {
  Network net = with_nodes(2 * 23);
  for (int k = 0; k < 23; ++k) net.add_vessel(100 - k, 2 * k, 2 * k + 1, mm(1), um(20), 1e-6, 1e6, 0);
  net.add_vessel(200, 44, 45, mm(1), um(20), 1e-6, 1e6, 0);  // the last pair twice: a part of 2
  NodeBoundary in;
  in.node = 20;  // the part of vessel 90
  in.waveform = Waveform::constant_value(1e-9);
  net.boundaries = {in};
  const NetworkStats s = compute_stats(net);
  ASSERT_EQ(s.parts_by_size.size(), 23u);
  EXPECT_EQ(s.parts_by_size[0].lowest_vessel_id, 78);  // vessels 78 and 200
  EXPECT_EQ(s.parts_by_size[0].vessels, 2u);
  for (std::size_t k = 1; k < 23; ++k) EXPECT_EQ(s.parts_by_size[k].lowest_vessel_id, 78 + static_cast<int>(k));
  const PartStats& fed = s.parts_by_size[12];
  EXPECT_EQ(fed.lowest_vessel_id, 90);
  EXPECT_FALSE(fed.flows_balance);
  EXPECT_DOUBLE_EQ(fed.net_inflow, 1e-9);
  std::ostringstream table;
  print_table(s, table, vstats_words());
  const std::string text = table.str();
  EXPECT_NE(text.find("  with vessel 97"), std::string::npos) << text;  // the twentieth
  EXPECT_EQ(text.find("  with vessel 98"), std::string::npos) << text;
  EXPECT_NE(text.find("  with vessel 90                1          2               1  no (net inflow 0.06 ml/min)\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("  with vessel 91                1          2               0  no (no boundary)\n"), std::string::npos)
      << text;
  EXPECT_NE(text.find("  3 more                        3          6               0  (--json lists them all)"),
            std::string::npos)
      << text;
  EXPECT_EQ(to_json(s)["connected_parts"].size(), 23u);
  EXPECT_EQ(to_json(s)["connected_parts"][12]["flows_balance"], false);
}

TEST(NetworkStats, EmptyNetwork) {
  const NetworkStats s = compute_stats(Network{});
  EXPECT_EQ(s.vessels, 0u);
  EXPECT_TRUE(s.generations.empty());
  EXPECT_EQ(s.capillary_generation_min, -1);
  const nlohmann::json j = to_json(s);
  EXPECT_TRUE(j["generations"].is_array());
  EXPECT_TRUE(j["generations"].empty());
  std::ostringstream table;
  print_table(s, table);
  EXPECT_NE(table.str().find("vessels"), std::string::npos);
}

TEST(NetworkStats, TableHasTotalsThenOneRowPerGeneration) {
  Network net = with_nodes(4);
  add(net, 0, 1, mm(10), um(600), 0);
  add(net, 1, 2, mm(5), um(40), 2);
  add(net, 1, 3, mm(5), um(20), 2);
  std::ostringstream out;
  print_table(compute_stats(net), out);
  const std::string table = out.str();

  EXPECT_NE(table.find("total length"), std::string::npos);
  EXPECT_NE(table.find(" ml)"), std::string::npos);
  EXPECT_LT(table.find("total volume"), table.find("D_median"));  // totals first
  // Generation 2's median, 30 um, printed in micrometres.
  EXPECT_NE(table.find("30.00"), std::string::npos);

  std::istringstream lines(table.substr(table.find("D_median")));
  std::string line;
  std::getline(lines, line);  // header
  std::getline(lines, line);  // units
  int rows = 0;
  std::size_t width = 0;
  while (std::getline(lines, line)) {
    if (rows == 0) width = line.size();
    EXPECT_EQ(line.size(), width) << "fixed-width columns";
    ++rows;
  }
  EXPECT_EQ(rows, 3);  // generations 0, 1 (empty), 2
}

TEST(NetworkStats, RejectsBrokenNetworks) {
  Network bad_node = with_nodes(2);
  add(bad_node, 0, 5, mm(1), um(10), 0);
  EXPECT_THROW(compute_stats(bad_node), InputError);

  Network bad_generation = with_nodes(2);
  add(bad_generation, 0, 1, mm(1), um(10), -1);
  EXPECT_THROW(compute_stats(bad_generation), InputError);

  Network bad_diameter = with_nodes(2);
  add(bad_diameter, 0, 1, mm(1), std::nan(""), 0);
  EXPECT_THROW(compute_stats(bad_diameter), InputError);
}

}  // namespace
}  // namespace hemotree
