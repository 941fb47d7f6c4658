// The vnet format: round trips, streaming through files, and clear refusals.
#include <cmath>
#include <cstdio>
#include <numbers>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "formats/json_pull.hpp"
#include "formats/network_io.hpp"
#include "formats/topology.hpp"
#include "generator/growth_rules.hpp"
#include "generator/tree_growth.hpp"
#include "generator/tree_layout.hpp"

using namespace hemotree;
namespace fs = std::filesystem;

namespace {

fs::path temp_path(const std::string& name) {
  return fs::temp_directory_path() / ("hemotree-test-" + std::to_string(::getpid()) + "-" + name);
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

Network grown_tree() {
  GrowthParameters p;
  p.root_diameter = 120e-6;
  p.min_diameter = 7e-6;
  Network net = grow_tree(default_rules(), p);
  lay_out_tree(net);
  net.provenance = {{"tool", "test"}, {"seed", 1}};
  return net;
}

std::string write_to_string(const Network& net, const std::string& name) {
  const fs::path path = temp_path(name);
  {
    OutputStream out(path.string());
    write_network(net, out);
    out.commit();
  }
  std::string text = slurp(path);
  fs::remove(path);
  return text;
}

// Expects parse_network(text) to throw an error whose message contains fragment.
void expect_refusal(const std::string& text, const std::string& fragment) {
  try {
    parse_network(text, "net.json");
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos)
        << "message: " << e.what() << "\nwanted: " << fragment;
    return;
  }
  ADD_FAILURE() << "accepted:\n" << text;
}

const char* minimal = R"({"format": "vnet", "version": 1,
 "nodes": [{"id": 10}, {"id": 11}, {"id": 12}, {"id": 13}],
 "vessels": [
  {"id": 1, "from": 10, "to": 11, "length": 0.01, "diameter": 1e-3,
   "wall_thickness": 1e-4, "youngs_modulus": 2e5},
  {"id": 2, "from": 11, "to": 12, "length": 0.01, "diameter": 6e-4,
   "wall_thickness": 1e-4, "youngs_modulus": 2e5},
  {"id": 3, "from": 11, "to": 13, "length": 0.01, "diameter": 5e-5,
   "wall_thickness": 1e-5, "youngs_modulus": 2e5}]})";

}  // namespace

TEST(NetworkFormat, RoundTripKeepsEveryValueAndRewritesByteIdentically) {
  const Network net = grown_tree();
  const std::string text = write_to_string(net, "a.json");
  const Network back = parse_network(text);
  ASSERT_EQ(back.vessel_count(), net.vessel_count());
  ASSERT_EQ(back.node_count(), net.node_count());
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    EXPECT_EQ(back.id[v], net.id[v]);
    EXPECT_EQ(back.node_id[back.from[v]], net.node_id[net.from[v]]);
    EXPECT_EQ(back.node_id[back.to[v]], net.node_id[net.to[v]]);
    EXPECT_NEAR(back.length[v], net.length[v], 5e-9 * net.length[v]);  // 9 significant digits
    EXPECT_NEAR(back.diameter[v], net.diameter[v], 5e-9 * net.diameter[v]);
    EXPECT_EQ(back.generation[v], net.generation[v]);
    EXPECT_EQ(back.vessel_class[v], net.vessel_class[v]);
  }
  EXPECT_EQ(back.provenance, net.provenance);
  EXPECT_EQ(write_to_string(back, "b.json"), text);
}

TEST(NetworkFormat, StreamsFromAFile) {
  const Network net = grown_tree();
  const fs::path path = temp_path("stream.json");
  {
    OutputStream out(path.string());
    write_network(net, out);
    out.commit();
  }
  const Network back = read_network(path.string());
  EXPECT_EQ(back.vessel_count(), net.vessel_count());
  fs::remove(path);
}

TEST(NetworkFormat, NodesMayBeLeftOutAndGenerationsAreComputed) {
  const Network net = parse_network(R"({"format":"vnet","version":1,"vessels":[
    {"id":5,"from":0,"to":1,"length":0.01,"diameter":1e-3},
    {"id":6,"from":1,"to":2,"length":0.01,"diameter":6e-4},
    {"id":7,"from":1,"to":3,"length":0.01,"diameter":6e-4},
    {"id":8,"from":3,"to":4,"length":0.01,"diameter":6e-4}]})");
  EXPECT_EQ(net.node_count(), 5u);
  EXPECT_FALSE(net.has_coordinates());
  EXPECT_EQ(net.generation, (std::vector<std::int32_t>{0, 1, 1, 2}));
  EXPECT_EQ(net.vessel_class[1], VesselClass::artery);
}

TEST(NetworkFormat, UnknownMembersAreIgnoredAndLaterStagesFieldsPassThrough) {
  std::string text = minimal;
  text.insert(text.find("\"id\": 2"), "\"colour\": [1, {\"a\": null}], ");
  text.insert(1, "\"annotations\": {\"vessel\": 1, \"note\": \"from a newer tool\"}, ");
  const Network net = parse_network(text);
  EXPECT_EQ(net.vessel_count(), 3u);
  EXPECT_EQ(net.extra.at("annotations").at("vessel"), 1);
  const Network again = parse_network(write_to_string(net, "extra.json"));
  EXPECT_EQ(again.extra, net.extra);
}

TEST(NetworkFormat, DirectTubeLawsAndMissingWallDataRoundTrip) {
  const Network net = parse_network(R"({"format":"vnet","version":1,"vessels":[
    {"id":1,"from":0,"to":1,"length":0.126,"diameter":0.006,"beta":3.2e6,"reference_pressure":10933},
    {"id":2,"from":1,"to":2,"length":0.1,"diameter":0.005}]})");
  ASSERT_EQ(net.beta.size(), 2u);
  EXPECT_DOUBLE_EQ(net.beta[0], 3.2e6);
  EXPECT_DOUBLE_EQ(net.reference_pressure[0], 10933);
  EXPECT_TRUE(std::isnan(net.beta[1]));
  const Network back = parse_network(write_to_string(net, "beta.json"));
  EXPECT_DOUBLE_EQ(back.beta[0], 3.2e6);
  EXPECT_TRUE(std::isnan(back.wall_thickness[1]));
  expect_refusal(R"({"format":"vnet","version":1,"vessels":[
    {"id":1,"from":0,"to":1,"length":0.1,"diameter":0.006,"beta":3.2e6}]})", "together");
}

TEST(NetworkFormat, SyntaxErrorsGiveTheirPosition) {
  expect_refusal("{\"format\": \"vnet\",\n \"version\": 1,,", "net.json:2:15");
  expect_refusal("{\"format\": \"vnet\", \"vessels\": [", "end of input");
  expect_refusal("", "net.json:1:1");
}

TEST(NetworkFormat, ContentErrorsNameTheVessel) {
  auto replaced = [](std::string from, std::string to) {
    std::string t = minimal;
    t.replace(t.find(from), from.size(), to);
    return t;
  };
  expect_refusal(replaced("\"length\": 0.01, \"diameter\": 6e-4", "\"length\": -1, \"diameter\": 6e-4"),
                 "net.json:6:45: vessel 2: \"length\" must lie in [1e-7, 10] m (got -1)");
  expect_refusal(replaced("\"diameter\": 5e-5,", ""), "vessel 3: missing \"diameter\"");
  expect_refusal(replaced("\"to\": 13", "\"to\": 99"), "vessel 3: unknown node 99");
  expect_refusal(replaced("\"length\": 0.01, \"diameter\": 6e-4", "\"length\": \"long\", \"diameter\": 6e-4"),
                 "vessel 2: \"length\" must be a number");
  expect_refusal(replaced("\"diameter\": 5e-5,", "\"diameter\": 5e-5, \"class\": \"artery\","),
                 "does not match its diameter");
  expect_refusal(replaced("\"vnet\"", "\"other\""), "not a hemotree network");
  expect_refusal(replaced("\"version\": 1", "\"version\": 7"), "version 7 is not supported");
  expect_refusal(replaced("{\"id\": 13}", "{\"id\": 12}"), "node id 12 appears twice");
  expect_refusal(R"({"format":"vnet","version":1})", "missing \"vessels\"");
}

// Issue 11, item 1: the message for a non-integer "id" was built from the key's view after
// next() had moved the scratch buffer (a longer escaped string reallocates it): garbage as
// the key's name, and a heap use after free under ASan. The issue's reproduction.
TEST(NetworkFormat, AKeysNameSurvivesTheValueAfterIt) {
  const std::string text = "{\"format\":\"vnet\",\"version\":1,\"provenance\":{\"a\":\"" +
                           std::string(40, 'p') + "\\n\"},\"vessels\":[{\"\\u0069d\":\"" +
                           std::string(200, 'v') + "\\n\"}]}";
  const std::string wanted = "net.json:1:116: vessels[0]: \"id\" must be an integer";
  try {
    parse_network(text, "net.json");
    ADD_FAILURE() << "accepted";
  } catch (const JsonError& e) {
    EXPECT_EQ(std::string(e.what()), wanted);
  }
  std::FILE* in = fmemopen(const_cast<char*>(text.data()), text.size(), "r");
  ASSERT_NE(in, nullptr);
  try {
    read_network(in, "net.json", 16);
    ADD_FAILURE() << "accepted";
  } catch (const JsonError& e) {
    EXPECT_EQ(std::string(e.what()), wanted);
  }
  std::fclose(in);
}

// The same at the stream's 1 MiB refill: the key "id" lies at the end of the first buffer,
// its string value runs into the next, whose bytes then took the key's place ("QQ").
TEST(NetworkFormat, AKeysNameSurvivesABufferRefill) {
  const std::string head = "{\"format\":\"vnet\",\"version\":1,\"provenance\":{\"a\":\"";
  const std::string tail = "\"},\"vessels\":[{\"id\":\"";
  const std::size_t pad = JsonPull::buffer_size - head.size() - tail.size() + 2;
  const std::string text = head + std::string(pad, 'p') + tail +
                           std::string(JsonPull::buffer_size, 'Q') + "\"}]}";
  ASSERT_EQ(text.find("\"id\""), JsonPull::buffer_size - 4);  // "id" ends the first buffer
  const fs::path path = temp_path("refill.json");
  {
    std::ofstream out(path, std::ios::binary);
    out << text;
  }
  try {
    read_network(path.string());
    ADD_FAILURE() << "accepted";
  } catch (const JsonError& e) {
    EXPECT_NE(std::string(e.what()).find(": vessels[0]: \"id\" must be an integer"),
              std::string::npos) << e.what();
  }
  fs::remove(path);
}

// Streamed through buffers of any size, a network reads as it does from memory.
TEST(NetworkFormat, TinyBuffersReadTheSameNetwork) {
  const std::string text = write_to_string(grown_tree(), "tiny.json");
  const Network expected = parse_network(text, "t.json");
  for (std::size_t buffer : {1, 3, 64, 4096}) {
    std::FILE* in = fmemopen(const_cast<char*>(text.data()), text.size(), "r");
    ASSERT_NE(in, nullptr);
    const Network got = read_network(in, "t.json", buffer);
    std::fclose(in);
    EXPECT_EQ(write_to_string(got, "tiny-again.json"), text) << "buffer " << buffer;
    EXPECT_EQ(got.vessel_count(), expected.vessel_count());
  }
}

TEST(Topology, RootedTreeChecksNameTheVesselAtFault) {
  auto tree_error = [](const std::string& vessels) {
    const Network net = parse_network(R"({"format":"vnet","version":1,"vessels":[)" + vessels + "]}");
    try {
      check_rooted_tree(net);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const std::string v1 = R"({"id":1,"from":0,"to":1,"length":1,"diameter":1e-3})";
  const std::string v2 = R"({"id":2,"from":1,"to":2,"length":1,"diameter":1e-3})";
  EXPECT_EQ(tree_error(v1 + "," + v2), "accepted");
  EXPECT_NE(tree_error(v1 + "," + v2 + R"(,{"id":3,"from":7,"to":8,"length":1,"diameter":1e-3})")
                .find("several roots"), std::string::npos);
  EXPECT_NE(tree_error(v1 + "," + v2 + R"(,{"id":3,"from":0,"to":2,"length":1,"diameter":1e-3})")
                .find("vessel 3"), std::string::npos);
  // A loop hanging off the tree: 5 -> 6 -> 5 is fed by no root.
  EXPECT_NE(tree_error(v1 + "," + v2 + R"(,{"id":3,"from":5,"to":6,"length":1,"diameter":1e-3},)" +
                       R"({"id":4,"from":6,"to":5,"length":1,"diameter":1e-3})")
                .find("not reached from the root"), std::string::npos);
}

TEST(OutputStream, AnUncommittedFileIsRemovedAndFullDisksAreReported) {
  const fs::path path = temp_path("partial.json");
  {
    OutputStream out(path.string());
    out << "{\"format\": ";
  }  // no commit: as if the writer failed half-way
  EXPECT_FALSE(fs::exists(path));
  for (const auto& entry : fs::directory_iterator(path.parent_path()))
    EXPECT_EQ(entry.path().string().find(path.filename().string()), std::string::npos);
  if (fs::is_character_file("/dev/full")) {
    EXPECT_THROW(
        {
          OutputStream out("/dev/full");
          for (int i = 0; i < 100000; ++i) out << "0123456789";
          out.commit();
        },
        IoError);
  }
}

// ---- version 2: boundaries at nodes, tapered vessels, the mean cell volume ---------------

namespace {

// A loop 10 -> 11 -> 12 -> 10 written partly against its flow, fed at 13, drained at 14.
const char* looped = R"({"format": "vnet", "version": 2,
 "blood": {"mean_cell_volume": 55e-18, "plasma_viscosity": 1.0466e-3},
 "boundaries": [
  {"node": 14, "type": "pressure", "pressure": 1333.22},
  {"node": 13, "type": "flow", "flow": 1e-12, "hematocrit": 0.45},
  {"node": 15, "type": "RCR", "R1": 1e9, "C": 1e-12, "R2": 4e9, "p_out": 500},
  {"node": 16, "type": "flow", "waveform": {"shape": "table", "period": 1, "time": [0, 0.5], "flow": [2e-12, -1e-12]}}],
 "vessels": [
  {"id": 1, "from": 13, "to": 10, "length": 1e-3, "diameter": 20e-6, "distal_diameter": 15e-6},
  {"id": 2, "from": 11, "to": 10, "length": 1e-3, "diameter": 20e-6},
  {"id": 3, "from": 11, "to": 12, "length": 1e-3, "diameter": 20e-6},
  {"id": 4, "from": 12, "to": 10, "length": 1e-3, "diameter": 20e-6},
  {"id": 5, "from": 12, "to": 14, "length": 1e-3, "diameter": 20e-6},
  {"id": 6, "from": 11, "to": 15, "length": 1e-3, "diameter": 20e-6},
  {"id": 7, "from": 16, "to": 11, "length": 1e-3, "diameter": 20e-6}]})";

}  // namespace

// The momentum flux's coefficient apart from the profile (openBF's code: 1 in the flux): read,
// written back, absent meaning alpha, and refused outside [1, 2].
TEST(NetworkFormat, MomentumFluxCoefficientApartFromTheProfile) {
  const auto with = [](const std::string& blood) {
    return R"({"format": "vnet", "version": 1, "blood": )" + blood +
           R"(, "vessels": [{"id": 0, "from": 0, "to": 1, "length": 0.01, "diameter": 0.001, "beta": 1e6, "reference_pressure": 0}]})";
  };
  const Network net = parse_network(with(R"({"alpha": 1.1, "momentum_flux_coefficient": 1})"));
  EXPECT_EQ(net.blood->alpha, 1.1);
  EXPECT_EQ(net.blood->momentum_alpha(), 1.0);
  EXPECT_EQ(to_json(*net.blood).at("momentum_flux_coefficient"), 1.0);
  const Network plain = parse_network(with(R"({"alpha": 1.1})"));
  EXPECT_EQ(plain.blood->momentum_alpha(), 1.1);
  EXPECT_FALSE(to_json(*plain.blood).contains("momentum_flux_coefficient"));  // files without it unchanged
  expect_refusal(with(R"({"momentum_flux_coefficient": 0.9})"), "\"momentum_flux_coefficient\" must lie in [1, 2]");
}

TEST(NetworkFormatVersion2, BoundariesAtNodesTaperAndCellVolumeRoundTrip) {
  const Network net = parse_network(looped);
  ASSERT_EQ(net.boundaries.size(), 4u);
  // Sorted by node (index): 13, 14, 15, 16 are nodes 4..7 in order of first appearance? The
  // reader makes nodes from the vessels' ids, sorted: 10..16 are indices 0..6.
  EXPECT_EQ(net.node_id[static_cast<std::size_t>(net.boundaries[0].node)], 13);
  EXPECT_EQ(net.boundaries[0].type, BoundaryType::flow);
  EXPECT_EQ(net.boundaries[0].waveform.shape, Waveform::Shape::constant);
  EXPECT_EQ(net.boundaries[0].waveform.mean_value(), 1e-12);
  EXPECT_EQ(net.boundaries[0].hematocrit, 0.45);
  EXPECT_EQ(net.boundaries[1].type, BoundaryType::pressure);
  EXPECT_EQ(net.boundaries[1].waveform(0.3), 1333.22);
  EXPECT_TRUE(std::isnan(net.boundaries[1].hematocrit));
  EXPECT_EQ(net.boundaries[2].type, BoundaryType::rcr);
  EXPECT_EQ(net.boundaries[2].outlet.r2, 4e9);
  EXPECT_EQ(net.boundaries[3].waveform.shape, Waveform::Shape::table);
  EXPECT_DOUBLE_EQ(net.boundaries[3].waveform(0.25), 0.5e-12);
  EXPECT_DOUBLE_EQ(net.boundaries[3].waveform.mean_value(), 0.5e-12);
  EXPECT_EQ(net.blood->mean_cell_volume, 55e-18);
  ASSERT_EQ(net.distal_diameter.size(), 7u);
  EXPECT_EQ(net.diameter_at_to(0), 15e-6);
  EXPECT_FALSE(net.is_tapered(1));
  EXPECT_NEAR(net.volume(0), std::numbers::pi / 12 * (400 + 300 + 225) * 1e-12 * 1e-3, 1e-24);
  // Every vessel has a generation, against its flow or not.
  for (std::size_t v = 0; v < net.vessel_count(); ++v) EXPECT_GE(net.generation[v], 0) << "vessel " << net.id[v];

  const std::string text = write_to_string(net, "v2.json");
  EXPECT_NE(text.find("\"version\": 2"), std::string::npos);
  EXPECT_NE(text.find("\"distal_diameter\":1.5e-05"), std::string::npos) << text;
  const Network back = parse_network(text);
  ASSERT_EQ(back.boundaries.size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(back.boundaries[k].node, net.boundaries[k].node);
    EXPECT_EQ(back.boundaries[k].type, net.boundaries[k].type);
    EXPECT_EQ(back.boundaries[k].waveform.mean_value(), net.boundaries[k].waveform.mean_value());
  }
  EXPECT_EQ(back.generation, net.generation);
  EXPECT_EQ(write_to_string(back, "v2b.json"), text);
}

// Writers write the oldest version that holds the content: a tree without node boundaries or
// tapers stays version 1, which older readers read.
TEST(NetworkFormatVersion2, AVersionOneNetworkIsWrittenAsVersionOne) {
  const std::string text = write_to_string(parse_network(minimal), "v1.json");
  EXPECT_NE(text.find("\"version\": 1"), std::string::npos);
  EXPECT_EQ(text.find("boundaries"), std::string::npos);
}

TEST(NetworkFormatVersion2, BoundaryErrorsNameTheNodeAndTheField) {
  auto with_boundary = [](const std::string& boundary) {
    std::string text = looped;
    const auto at = text.find("\"boundaries\": [") + 15;
    return text.insert(at, boundary + ",\n");
  };
  expect_refusal(with_boundary(R"({"node": 99, "type": "flow", "flow": 1e-12})"), "boundaries[0]: unknown node 99");
  expect_refusal(with_boundary(R"({"node": 10, "type": "suction"})"),
                 "\"type\" must be flow, pressure, RCR, R or reflection (got \"suction\")");
  expect_refusal(with_boundary(R"({"node": 10, "type": "flow"})"),
                 "a flow boundary needs \"flow\" (constant) or \"waveform\", one of them");
  expect_refusal(with_boundary(R"({"node": 10, "type": "pressure", "pressure": 1e9})"),
                 "(node 10): \"pressure\" must lie in [-1e5, 1e5] Pa (got 1e9)");
  expect_refusal(with_boundary(R"({"node": 10, "type": "R", "R": 1e9, "hematocrit": 0.4})"),
                 "\"hematocrit\" belongs to flow and pressure boundaries");
  expect_refusal(with_boundary(R"({"node": 13, "type": "R", "R": 1e9})"),
                 "node 13 has two boundary conditions (R and flow): one per node");
  expect_refusal(with_boundary(R"({"node": "13", "type": "R", "R": 1e9})"), "\"node\" must be a node id");
  std::string cells = looped;
  cells.replace(cells.find("55e-18"), 6, "5e-18");
  expect_refusal(cells, "\"mean_cell_volume\" must lie in [1.5e-17, 2e-16] m^3 (got 5e-18)");
}
