// Secomb's network.dat: hand-written files with numbers worked out by hand, every refusal's
// exact message, the rat mesentery (when the shared networks are present) and the round trip
// through write_secomb.
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "exchange/secomb.hpp"
#include "tests/shared_networks.hpp"
#include "formats/network_io.hpp"

using namespace hemotree;
namespace fs = std::filesystem;

namespace {

constexpr double pa_per_mmhg = 133.322387415;  // 13.5951 g/cm^3 x 9.80665 m/s^2 x 1 mm

fs::path temp_path(const std::string& name) {
  return fs::temp_directory_path() / ("hemotree-secomb-" + std::to_string(::getpid()) + "-" + name);
}

// Writes text to a temporary network.dat, removed when the test ends.
struct TempFile {
  explicit TempFile(const std::string& text, const std::string& name = "network.dat") : path(temp_path(name)) {
    std::ofstream(path, std::ios::binary) << text;
  }
  ~TempFile() { fs::remove(path); }
  fs::path path;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

struct Imported {
  Network net;
  std::vector<std::string> notes;
};

Imported import(const fs::path& path, ImportOptions options = {}) {
  Imported result;
  options.note = [&](const std::string& line) { result.notes.push_back(line); };
  result.net = read_secomb(path.string(), options);
  return result;
}

bool has_note(const Imported& imported, const std::string& fragment) {
  for (const std::string& n : imported.notes)
    if (n.find(fragment) != std::string::npos) return true;
  return false;
}

// A header as NetFlow's example has it, with the segment count on line 7.
std::string header(int segments) {
  return "Test network\n"
         "1000. 1000. 100. box dimensions in microns\n"
         "10 10 1 number of tissue points in x,y,z directions\n"
         "100.\touter bound distance\n"
         "150.\tmax. segment length\n"
         "4\t\tmaximum number of segments per node\n" +
         std::to_string(segments) + "\ttotal number of segments\n"
         "SegName Type StartNode EndNode Diam   Flow[nl/min]    Hd\n";
}

// Three segments in a row, 1 -> 2 -> 3 -> 4, of lengths 500 um (a 3-4-5 triangle), 120 um
// (along z) and 70 um (2-3-6-7 scaled by 10); 6 nl/min flowing in at node 1 with hematocrit
// 0.45, 15 mmHg at node 4.
const std::string segments_3 =
    "10 5 1 2 20.0 0.0 0.0 *\n"
    "11 4 2 3 15.0 0.0 0.0 *\n"
    "12 5 3 4 8.0 0.0 0.0 *\n";
const std::string nodes_4 =
    "4 number of nodes\n"
    "Name\tx\ty\tz\n"
    "1 0.0 0.0 0.0 *\n"
    "2 300.0 400.0 0.0 *\n"
    "3 300.0 400.0 120.0 *\n"
    "4 320.0 430.0 180.0 *\n";
const std::string boundaries_2 =
    "2 Total number of boundary nodes\n"
    "Node\t Bctype\t Press/Flow\t HD\t PO2\n"
    "1 2 6.0 0.45 40.0 *\n"
    "4 0 15.0 0.3 40.0 *\n";
const std::string three_segments = header(3) + segments_3 + nodes_4 + boundaries_2;

fs::path mesentery_path() { return shared_mesentery(); }

// Expects read_secomb to refuse text with exactly "PATH:" + message.
void expect_refusal(const std::string& text, const std::string& message) {
  TempFile file(text);
  try {
    read_secomb(file.path.string(), ImportOptions{});
    ADD_FAILURE() << "accepted; wanted: " << message;
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), file.path.string() + ":" + message);
  }
}

}  // namespace

TEST(ImportSecomb, ThreeSegmentsIdsLengthsAndUnits) {
  TempFile file(three_segments);
  const Imported imported = import(file.path);
  const Network& net = imported.net;

  ASSERT_EQ(net.vessel_count(), 3u);
  ASSERT_EQ(net.node_count(), 4u);
  EXPECT_EQ(net.node_id, (std::vector<std::int64_t>{1, 2, 3, 4}));
  EXPECT_EQ(net.id, (std::vector<std::int64_t>{10, 11, 12}));
  EXPECT_EQ(net.from, (std::vector<std::int32_t>{0, 1, 2}));
  EXPECT_EQ(net.to, (std::vector<std::int32_t>{1, 2, 3}));
  // Lengths from the coordinates: sqrt(300^2 + 400^2), 120, sqrt(20^2 + 30^2 + 60^2) um.
  EXPECT_DOUBLE_EQ(net.length[0], 500e-6);
  EXPECT_DOUBLE_EQ(net.length[1], 120e-6);
  EXPECT_DOUBLE_EQ(net.length[2], 70e-6);
  EXPECT_DOUBLE_EQ(net.diameter[0], 20e-6);
  EXPECT_DOUBLE_EQ(net.diameter[1], 15e-6);
  EXPECT_DOUBLE_EQ(net.diameter[2], 8e-6);
  EXPECT_EQ(net.vessel_class[0], VesselClass::arteriole);
  EXPECT_EQ(net.vessel_class[2], VesselClass::capillary);
  EXPECT_DOUBLE_EQ(net.x[3], 320e-6);
  EXPECT_DOUBLE_EQ(net.y[3], 430e-6);
  EXPECT_DOUBLE_EQ(net.z[3], 180e-6);
  // Counted from the inflow node 1.
  EXPECT_EQ(net.generation, (std::vector<std::int32_t>{0, 1, 2}));
  // Walls filled from hemotree's laws, blood left to the user.
  for (std::size_t v = 0; v < 3; ++v) {
    EXPECT_GT(net.wall_thickness[v], 0);
    EXPECT_GT(net.youngs_modulus[v], 0);
  }
  EXPECT_FALSE(net.blood.has_value());
  EXPECT_FALSE(net.inlet.has_value());
  EXPECT_TRUE(net.outlets.empty());

  ASSERT_EQ(net.boundaries.size(), 2u);
  const NodeBoundary& in = net.boundaries[0];
  EXPECT_EQ(in.node, 0);
  EXPECT_EQ(in.type, BoundaryType::flow);
  EXPECT_EQ(in.waveform.shape, Waveform::Shape::constant);
  EXPECT_DOUBLE_EQ(in.waveform.mean, 1e-13);  // 6 nl/min = 6e-12 m^3 / 60 s
  EXPECT_DOUBLE_EQ(in.hematocrit, 0.45);
  const NodeBoundary& p = net.boundaries[1];
  EXPECT_EQ(p.node, 3);
  EXPECT_EQ(p.type, BoundaryType::pressure);
  EXPECT_DOUBLE_EQ(p.waveform.mean, 15 * pa_per_mmhg);  // 1999.835811225 Pa
  EXPECT_NEAR(p.waveform.mean, 1999.835811225, 1e-9);
  EXPECT_DOUBLE_EQ(p.hematocrit, 0.3);

  EXPECT_EQ(net.provenance.at("tool"), "vimport");
  EXPECT_EQ(net.provenance.at("format"), "secomb");
  EXPECT_EQ(net.provenance.at("source"), file.path.string());
  EXPECT_EQ(net.provenance.at("title"), "Test network");
  EXPECT_TRUE(has_note(imported, "read 3 segments, 4 nodes and 2 boundary nodes (1 pressure, 1 inflow, 0 outflow"));
  EXPECT_TRUE(has_note(imported, "ignored the solute columns (PO2, ...) of 2 boundary nodes"));
  EXPECT_TRUE(has_note(imported, "wall thickness"));
  EXPECT_FALSE(has_note(imported, "flow and hematocrit columns"));
}

TEST(ImportSecomb, OutflowSignAndHematocrit) {
  // NetFlow's sign: positive flows into the network; an outflow's hematocrit is ignored.
  const std::string text = header(3) + segments_3 + nodes_4 +
                           "2 Total number of boundary nodes\nNode Bctype Press/Flow HD\n"
                           "1 0 40.0 0.5\n"
                           "4 2 -3.0 0.7\n";
  TempFile file(text);
  const Imported imported = import(file.path);
  const Network& net = imported.net;
  ASSERT_EQ(net.boundaries.size(), 2u);
  EXPECT_EQ(net.boundaries[0].type, BoundaryType::pressure);
  EXPECT_DOUBLE_EQ(net.boundaries[0].waveform.mean, 40 * pa_per_mmhg);
  EXPECT_DOUBLE_EQ(net.boundaries[0].hematocrit, 0.5);
  EXPECT_EQ(net.boundaries[1].type, BoundaryType::flow);
  EXPECT_DOUBLE_EQ(net.boundaries[1].waveform.mean, -3e-12 / 60);
  EXPECT_TRUE(std::isnan(net.boundaries[1].hematocrit));
  // No inflow: counted from every boundary node, so from both ends.
  EXPECT_EQ(net.generation, (std::vector<std::int32_t>{0, 1, 0}));
  EXPECT_TRUE(has_note(imported, "from the boundary nodes"));
  EXPECT_FALSE(has_note(imported, "solute"));
}

// A flow too small for m^3/s (1e-320 nl/min is 0 there) is no inflow: no hematocrit, and
// generations not counted from it, so that vexport secomb's file (flow 0) reads back the same
// (found by tests/fuzz/fuzz_import_secomb.cpp; reproducer in tests/fuzz/regressions).
TEST(ImportSecomb, AFlowThatUnderflowsIsNoInflow) {
  const std::string text = header(3) + segments_3 + nodes_4 +
                           "2 Total number of boundary nodes\nNode Bctype Press/Flow HD\n"
                           "1 2 6.01e-320 0.45\n"
                           "4 0 15.0 0.3\n";
  TempFile file(text);
  const Network net = import(file.path).net;
  ASSERT_EQ(net.boundaries.size(), 2u);
  EXPECT_EQ(net.boundaries[0].waveform.mean, 0.0);
  EXPECT_TRUE(std::isnan(net.boundaries[0].hematocrit));
  EXPECT_EQ(net.generation, (std::vector<std::int32_t>{0, 1, 0}));  // from both ends, as without inflow
}

TEST(ImportSecomb, SkippedTypesUnusedNodesAndResults) {
  // Segment 13 (type 3) is skipped as NetFlow skips it, and node 5 that only it joins is
  // left out; nonzero flow columns are NetFlow's results and are noted, not used.
  const std::string text = header(4) + segments_3 + "13 3 4 5 9.0 1.5 0.4\n" +
                           "5 number of nodes\nName x y z\n1 0 0 0\n2 300 400 0\n3 300 400 120\n"
                           "4 320 430 180\n5 400 430 180\n" +
                           boundaries_2 + "\nextra line\n";
  TempFile file(text);
  const Imported imported = import(file.path);
  EXPECT_EQ(imported.net.vessel_count(), 3u);
  EXPECT_EQ(imported.net.node_count(), 4u);
  EXPECT_TRUE(has_note(imported, "skipped 1 segment of a type other than 4 or 5, as NetFlow does: 13"));
  EXPECT_TRUE(has_note(imported, "left out 1 node that no segment of type 4 or 5 joins: 5"));
  EXPECT_TRUE(has_note(imported, "ignored the flow and hematocrit columns of 1 segment"));
  EXPECT_TRUE(has_note(imported, "ignored 1 line after the last boundary node (from line 25)"));
}

TEST(ImportSecomb, WallOptions) {
  TempFile file(three_segments);
  ImportOptions options;
  options.wall_ratio = 0.1;
  options.youngs_modulus = 4e5;
  const Imported imported = import(file.path, options);
  EXPECT_DOUBLE_EQ(imported.net.wall_thickness[0], 2e-6);
  EXPECT_DOUBLE_EQ(imported.net.youngs_modulus[2], 4e5);
}

TEST(ImportSecomb, Refusals) {
  const std::string h = header(3);
  // Numbers and names.
  expect_refusal(h + "10 5 1 2 2O.0 0.0 0.0\n" + segments_3.substr(segments_3.find('\n') + 1) + nodes_4 + boundaries_2,
                 "9: segment 10: the diameter must be a number (got '2O.0')");
  expect_refusal(h + "10 5 1 2 20.0 0.0\n", "9: a segment line needs 7 fields: name, type, from node, to node, "
                                            "diameter [um], flow [nl/min], hematocrit; found 6 (segment 1 of the 3 "
                                            "announced on line 7)");
  expect_refusal(h + "010 5 1 2 20.0 0.0 0.0\n",
                 "9: the segment name (segment 1 of the 3 announced on line 7) must be a decimal integer (got '010')");
  expect_refusal(h + "10 5 1 2 1.0 0.0 0.0\n", "9: segment 10: the diameter must lie in [2, 5e5] um (got 1)");
  expect_refusal(h + "10 5 1 1 20.0 0.0 0.0\n", "9: segment 10 joins node 1 to itself (zero length)");
  // Duplicates.
  expect_refusal(h + "10 5 1 2 20 0 0\n10 5 2 3 15 0 0\n", "10: segment 10 appears twice (first on line 9)");
  expect_refusal(h + segments_3 + "4 number of nodes\nName x y z\n1 0 0 0\n2 300 400 0\n1 300 400 120\n",
                 "16: node 1 appears twice (first on line 14)");
  expect_refusal(h + segments_3 + nodes_4 + "2 boundary nodes\nNode Bctype Press/Flow HD\n1 2 6 0.4\n1 0 15 0.4\n",
                 "21: boundary node 1 appears twice (first on line 20)");
  // Nodes that are not there, or not joined.
  expect_refusal(h + "10 5 1 2 20 0 0\n11 5 2 7 15 0 0\n12 5 3 4 8 0 0\n" + nodes_4 + boundaries_2,
                 "10: segment 11: node 7 is not in the node list");
  expect_refusal(h + segments_3 + nodes_4 + "1 boundary nodes\nNode Bctype Press/Flow HD\n9 2 6 0.4\n",
                 "20: boundary node 9 is not in the node list");
  expect_refusal(h + segments_3 + "4 number of nodes\nName x y z\n1 0 0 0\n2 300 400 0\n3 300 400 0\n4 320 430 180\n" +
                     boundaries_2,
                 "10: segment 11 has zero length: its nodes 2 and 3 lie at the same point");
  // Boundary types and values.
  expect_refusal(h + segments_3 + nodes_4 + "1 boundary nodes\nNode Bctype Press/Flow HD\n1 1 6 0.4\n",
                 "20: boundary node 1: bctype 1 is not one NetFlow defines (0: pressure [mmHg], 2: inflow [nl/min], "
                 "negative for an outflow)");
  expect_refusal(h + segments_3 + nodes_4 + "1 boundary nodes\nNode Bctype Press/Flow HD\n1 2 6 1.2\n",
                 "20: boundary node 1: the hematocrit must lie in [0, 0.9] (discharge, inflowing blood) (got 1.2)");
  // Sections and counts.
  expect_refusal(h + segments_3 + nodes_4, "17: the file ends where the total number of boundary nodes should follow");
  expect_refusal(header(4) + segments_3 + nodes_4 + boundaries_2,
                 "12: a segment line needs 7 fields: name, type, from node, to node, diameter [um], flow [nl/min], "
                 "hematocrit; found 4 (segment 4 of the 4 announced on line 7)");
  expect_refusal(header(2) + segments_3 + nodes_4 + boundaries_2,
                 "11: a segment line where the number of nodes should be: line 7 announced 2 segments, the file has more");
  expect_refusal(h + segments_3 + "5 number of nodes\nName x y z\n1 0 0 0\n2 300 400 0\n3 300 400 120\n4 320 430 180\n",
                 "17: the file ends after 4 of the 5 nodes announced on line 12");
  expect_refusal(h + segments_3 + "4 number of nodes\n1 0 0 0\n2 300 400 0\n",
                 "13: expected the nodes' column names (Name x y z) after the count, found numbers; NetFlow skips this "
                 "line unread");
  expect_refusal("Test network\n1000. 1000. box dimensions\n",
                 "2: the box dimensions (three numbers [um]) must be a number (got 'box')");
  // A corrupt count is found wrong at the end of the file, without reserving room for it.
  expect_refusal(header(2147483647) + segments_3,
                 "11: the file ends after 3 of the 2147483647 segments announced on line 7");
  expect_refusal("Test network\n1000. 1000. 100.\n10 10 1\n100.\n150.\n4\nmany\n",
                 "7: the total number of segments must be a decimal integer (got 'many')");
}

TEST(ImportSecomb, UnreadableFiles) {
  EXPECT_THROW(read_secomb("/nonexistent/network.dat", ImportOptions{}), IoError);
  EXPECT_THROW(read_secomb(fs::temp_directory_path().string(), ImportOptions{}), IoError);
  TempFile empty("");
  try {
    read_secomb(empty.path.string(), ImportOptions{});
    ADD_FAILURE() << "accepted an empty file";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), empty.path.string() + ": empty file (network.dat begins with a title line)");
  }
}

TEST(ExportSecomb, ThreeSegmentsText) {
  TempFile file(three_segments);
  const Network net = import(file.path).net;
  const fs::path out_path = temp_path("out.dat");
  {
    OutputStream out(out_path.string());
    write_secomb(net, out);
    out.commit();
  }
  const std::string text = slurp(out_path);
  fs::remove(out_path);
  EXPECT_EQ(text,
            "Network written by hemotree: 3 segments, 4 nodes\n"
            "320 430 180 box dimensions in microns\n"
            "1 1 1 number of tissue points in x,y,z directions\n"
            "100 outer bound distance\n"
            "500 max. segment length\n"
            "2 maximum number of segments per node\n"
            "3 total number of segments\n"
            "SegName Type StartNode EndNode Diam Flow[nl/min] Hd\n"
            "10 5 1 2 20 0 0\n"
            "11 5 2 3 15 0 0\n"
            "12 5 3 4 8 0 0\n"
            "4 number of nodes\n"
            "Name x y z\n"
            "1 0.000000 0.000000 0.000000\n"
            "2 300.000000 400.000000 0.000000\n"
            "3 300.000000 400.000000 120.000000\n"
            "4 320.000000 430.000000 180.000000\n"
            "2 total number of boundary nodes\n"
            "Node Bctype Press/Flow HD\n"
            "1 2 6 0.45\n"
            "4 0 15 0.3\n");
}

TEST(ExportSecomb, Refusals) {
  TempFile file(three_segments);
  const Network base = import(file.path).net;
  const auto refusal = [](const Network& net) -> std::string {
    OutputStream out(temp_path("refused.dat").string());
    try {
      write_secomb(net, out);
    } catch (const InputError& e) {
      return e.what();
    }
    return "accepted";
  };
  Network rcr = base;
  rcr.boundaries[1].type = BoundaryType::rcr;
  rcr.boundaries[1].outlet.type = BoundaryType::rcr;
  EXPECT_EQ(refusal(rcr), "node 4: an outlet model (RCR) cannot be written to network.dat, which holds pressures and flows only");
  Network pulsing = base;
  pulsing.boundaries[0].waveform.shape = Waveform::Shape::half_sine;
  EXPECT_EQ(refusal(pulsing), "node 1: a time-varying flow cannot be written to network.dat, which holds steady values only");
  Network curved = base;
  curved.length[1] = 130e-6;
  EXPECT_EQ(refusal(curved), "vessel 11: length 130 um differs from the distance between its nodes (120 um), and "
                             "NetFlow takes lengths from the coordinates");
  Network tapered = base;
  tapered.distal_diameter = {std::nan(""), 10e-6, std::nan("")};
  EXPECT_EQ(refusal(tapered), "vessel 11 tapers, and network.dat holds one diameter a segment");
  Network inner = base;
  inner.boundaries[0].node = 1;
  EXPECT_EQ(refusal(inner), "node 2: a boundary where 2 vessels meet; NetFlow takes boundary nodes at the end of one segment");
  Network bare = base;
  bare.x.clear();
  bare.y.clear();
  bare.z.clear();
  EXPECT_EQ(refusal(bare), "the network has no node coordinates, and network.dat gives each segment's length as the "
                           "distance between its nodes (NetFlow computes it so): nothing to write");
  Network big = base;
  big.id[0] = 3'000'000'000LL;
  EXPECT_EQ(refusal(big), "vessel 3000000000: network.dat names are 32-bit integers (NetFlow reads them with %i); "
                          "this id does not fit");
}

TEST(ImportSecomb, RatMesentery) {
  const fs::path path = mesentery_path();
  if (!fs::exists(path)) GTEST_SKIP() << path << " absent (the shared public networks)";
  const Imported imported = import(path);
  const Network& net = imported.net;
  // The file's own counts: 1130 segments (all of type 5), 972 nodes, 36 boundary nodes.
  EXPECT_EQ(net.vessel_count(), 1130u);
  EXPECT_EQ(net.node_count(), 972u);
  ASSERT_EQ(net.boundaries.size(), 36u);
  int pressures = 0, inflows = 0, outflows = 0;
  double net_inflow = 0;
  for (const NodeBoundary& b : net.boundaries) {
    if (b.type == BoundaryType::pressure) {
      ++pressures;
      EXPECT_EQ(net.node_id[static_cast<std::size_t>(b.node)], 825);
      EXPECT_DOUBLE_EQ(b.waveform.mean, 13.8 * pa_per_mmhg);
      continue;
    }
    ASSERT_EQ(b.type, BoundaryType::flow);
    (b.waveform.mean > 0 ? inflows : outflows)++;
    EXPECT_EQ(b.waveform.mean > 0, !std::isnan(b.hematocrit));
    net_inflow += b.waveform.mean;
  }
  EXPECT_EQ(pressures, 1);
  EXPECT_EQ(inflows, 31);
  EXPECT_EQ(outflows, 4);
  // The flows' sum, added up from the file's column: 722.699405 nl/min (leaves at node 825).
  EXPECT_NEAR(net_inflow, 722.699405e-12 / 60, 1e-9 * 722.7e-12 / 60);
  // Segment 1 runs from node 830 (139.5625... see the file) with diameter 27.65 um.
  EXPECT_EQ(net.id[0], 1);
  EXPECT_EQ(net.node_id[static_cast<std::size_t>(net.from[0])], 830);
  EXPECT_DOUBLE_EQ(net.diameter[0], 27.65e-6);
  // Total length, summed from the node coordinates in double precision by a separate
  // script: 150114.21056364788 um.
  double total = 0;
  for (double l : net.length) total += l;
  EXPECT_NEAR(total, 150114.21056364788e-6, 1e-12);
  for (std::int32_t g : net.generation) {
    EXPECT_GE(g, 0);
    EXPECT_LT(g, 1130);
  }
  EXPECT_TRUE(has_note(imported, "ignored the solute columns (PO2, ...) of 36 boundary nodes"));

  // What vimport writes reads back.
  const fs::path json = temp_path("mesentery.json");
  {
    OutputStream out(json.string());
    write_network(net, out);
    out.commit();
  }
  const Network back = read_network(json.string());
  fs::remove(json);
  EXPECT_EQ(back.vessel_count(), 1130u);
  EXPECT_EQ(back.boundaries.size(), 36u);
  EXPECT_EQ(back.generation, net.generation);
}

TEST(ExportSecomb, MesenteryRoundTrip) {
  const fs::path path = mesentery_path();
  if (!fs::exists(path)) GTEST_SKIP() << path << " absent (the shared public networks)";
  const Network first = import(path).net;
  const fs::path written = temp_path("roundtrip.dat");
  {
    OutputStream out(written.string());
    write_secomb(first, out);
    out.commit();
  }
  const Network second = import(written).net;
  fs::remove(written);
  // Written with 9 significant digits: equal to within 5e-9, relative.
  const auto same = [](double a, double b) { return std::abs(a - b) <= 5e-9 * std::max(std::abs(a), std::abs(b)); };
  ASSERT_EQ(second.vessel_count(), first.vessel_count());
  ASSERT_EQ(second.node_count(), first.node_count());
  EXPECT_EQ(second.id, first.id);
  EXPECT_EQ(second.node_id, first.node_id);
  EXPECT_EQ(second.from, first.from);
  EXPECT_EQ(second.to, first.to);
  EXPECT_EQ(second.generation, first.generation);
  for (std::size_t v = 0; v < first.vessel_count(); ++v) {
    EXPECT_TRUE(same(second.length[v], first.length[v])) << v;
    EXPECT_TRUE(same(second.diameter[v], first.diameter[v])) << v;
  }
  for (std::size_t n = 0; n < first.node_count(); ++n)
    EXPECT_TRUE(same(second.x[n], first.x[n]) && same(second.y[n], first.y[n]) && same(second.z[n], first.z[n])) << n;
  ASSERT_EQ(second.boundaries.size(), first.boundaries.size());
  for (std::size_t k = 0; k < first.boundaries.size(); ++k) {
    const NodeBoundary &a = first.boundaries[k], &b = second.boundaries[k];
    EXPECT_EQ(b.node, a.node);
    EXPECT_EQ(b.type, a.type);
    EXPECT_TRUE(same(b.waveform.mean, a.waveform.mean)) << k;
    EXPECT_EQ(std::isnan(b.hematocrit), std::isnan(a.hematocrit));
    if (!std::isnan(a.hematocrit)) {
      EXPECT_TRUE(same(b.hematocrit, a.hematocrit)) << k;
    }
  }
}
