// Exports read back: VTK through a small XML parser, GraphML through Boost's reader,
// dot and CSV as text.
#include <iterator>
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <boost/graph/adjacency_list.hpp>
#include <boost/graph/graphml.hpp>

#include "core/errors.hpp"
#include "formats/exports.hpp"
#include "tests/xml_reader.hpp"

namespace hemotree {
namespace {
using test_xml::XmlElement;
using test_xml::XmlParser;

// A root and its subtree, with the nodes numbered so that the vessels' source nodes are
// not in vessel order: the CSR graph behind GraphML/dot must still pair each edge with its
// own vessel. Values carry more than 6 digits to catch iostream's default precision.
Network sample_network(bool with_coordinates = true) {
  Network net;
  auto node = [&](std::int64_t id, double x, double y, double z) {
    return with_coordinates ? net.add_node(id, x, y, z) : net.add_node(id);
  };
  const auto a = node(10, 0.0, 0.0, 0.0123456789012);
  const auto b = node(11, 0.001, 0.0, 0.015);
  const auto root = node(12, 0.0, 0.0, 0.0);
  const auto c = node(13, -0.001, 0.0, 0.015);
  const auto d = node(14, 0.0015, -2.5e-4, 0.017);
  net.add_vessel(100, root, a, 0.0123456789012, 1.23456789012e-3, 1.5e-4, 1e6, 0);  // artery
  net.add_vessel(101, a, b, 0.0031, 4.0e-4, 6.0e-5, 2.5e5, 1);                      // small artery
  net.add_vessel(102, a, c, 0.0032, 5.0e-5, 1.0e-5, 2.5e5, 1);                      // arteriole
  net.add_vessel(103, b, d, 0.0021, 8.0e-6, 1.0e-6, 1.25e5, 2);                     // capillary
  return net;
}

const std::filesystem::path& scratch_dir() {
  static const std::filesystem::path dir = [] {
    auto d = std::filesystem::path(HEMOTREE_BINARY_DIR) / "test_exports_scratch";
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Writes through a real file and commit(), as the tools do, and returns what landed.
std::string export_text(const std::string& file, const std::function<void(OutputStream&)>& write) {
  const auto path = scratch_dir() / file;
  OutputStream out(path.string());
  write(out);
  out.commit();
  return read_text(path);
}

void expect_close(double expected, double actual, const std::string& what) {
  // 9 significant digits survive; 6 would not.
  EXPECT_NEAR(expected, actual, 1e-8 * std::abs(expected)) << what;
}

std::vector<double> numbers(const std::string& text) {
  std::istringstream in(text);
  std::vector<double> values;
  for (double v; in >> v;) values.push_back(v);
  EXPECT_TRUE(in.eof()) << "not a number in: " << text.substr(0, 80);
  return values;
}

// --- VTK -------------------------------------------------------------------------------------

TEST(ExportVtk, IsWellFormedPolyDataWithTheNetworksNumbers) {
  const Network net = sample_network();
  const std::vector<double> pressure = {1200.5, 1100.25, 1050.125, 990.0625};
  const std::string text = export_text("sample.vtp", [&](OutputStream& out) {
    write_vtk(net, out, {CellField{"pressure_pa", pressure}});
  });
  EXPECT_EQ(text.find("<!--"), std::string::npos);

  const XmlElement file = XmlParser(text).document();
  EXPECT_EQ(file.name, "VTKFile");
  EXPECT_EQ(file.attributes.at("type"), "PolyData");
  EXPECT_EQ(file.attributes.at("version"), "1.0");
  EXPECT_EQ(file.attributes.at("byte_order"), "LittleEndian");
  EXPECT_EQ(file.attributes.at("header_type"), "UInt64");

  const XmlElement& piece = file.child("PolyData").child("Piece");
  EXPECT_EQ(piece.attributes.at("NumberOfPoints"), "5");
  EXPECT_EQ(piece.attributes.at("NumberOfLines"), "4");
  EXPECT_EQ(piece.attributes.at("NumberOfVerts"), "0");
  EXPECT_EQ(piece.attributes.at("NumberOfPolys"), "0");
  EXPECT_EQ(piece.attributes.at("NumberOfStrips"), "0");

  const XmlElement& points = piece.child("Points").child("DataArray");
  EXPECT_EQ(points.attributes.at("type"), "Float64");
  EXPECT_EQ(points.attributes.at("NumberOfComponents"), "3");
  EXPECT_EQ(points.attributes.at("format"), "ascii");
  const auto xyz = numbers(points.text);
  ASSERT_EQ(xyz.size(), 3 * net.node_count());
  for (std::size_t n = 0; n < net.node_count(); ++n) {
    expect_close(net.x[n], xyz[3 * n], "x");
    expect_close(net.y[n], xyz[3 * n + 1], "y");
    expect_close(net.z[n], xyz[3 * n + 2], "z");
  }

  const XmlElement& lines = piece.child("Lines");
  ASSERT_EQ(lines.children.size(), 2u);
  EXPECT_EQ(lines.children[0].attributes.at("Name"), "connectivity");
  EXPECT_EQ(lines.children[1].attributes.at("Name"), "offsets");
  EXPECT_EQ(numbers(lines.children[0].text), (std::vector<double>{2, 0, 0, 1, 0, 3, 1, 4}));
  EXPECT_EQ(numbers(lines.children[1].text), (std::vector<double>{2, 4, 6, 8}));

  const XmlElement& cells = piece.child("CellData");
  EXPECT_EQ(cells.attributes.at("Scalars"), "diameter");
  struct Expected {
    std::string name, type;
    std::vector<double> values;
  };
  auto as_doubles = [](const auto& column) {
    return std::vector<double>(column.begin(), column.end());
  };
  const std::vector<Expected> expected = {
      {"id", "Int64", as_doubles(net.id)},
      {"diameter", "Float64", net.diameter},
      {"length", "Float64", net.length},
      {"wall_thickness", "Float64", net.wall_thickness},
      {"youngs_modulus", "Float64", net.youngs_modulus},
      {"generation", "Int32", as_doubles(net.generation)},
      {"class", "UInt8", {0, 1, 2, 3}},
      {"pressure_pa", "Float64", pressure},
  };
  ASSERT_EQ(cells.children.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const XmlElement& array = cells.children[i];
    EXPECT_EQ(array.name, "DataArray");
    EXPECT_EQ(array.attributes.at("Name"), expected[i].name);
    EXPECT_EQ(array.attributes.at("type"), expected[i].type) << expected[i].name;
    EXPECT_EQ(array.attributes.count("NumberOfComponents"), 0u) << expected[i].name;
    const auto values = numbers(array.text);
    ASSERT_EQ(values.size(), net.vessel_count()) << expected[i].name;
    for (std::size_t v = 0; v < values.size(); ++v)
      expect_close(expected[i].values[v], values[v], expected[i].name);
  }
}

// A measured network's boundary nodes as point data, a tapered vessel's distal diameter as
// cell data (every vessel: its diameter at `to`).
TEST(ExportVtk, BoundaryNodesAndTapersAreWrittenWhereTheNetworkHasThem) {
  Network net = sample_network();
  net.distal_diameter = {1.0e-3, std::numeric_limits<double>::quiet_NaN(), 4.0e-5,
                         std::numeric_limits<double>::quiet_NaN()};
  NodeBoundary in, out_pressure;
  in.node = 2;  // the root's node (id 12)
  in.type = BoundaryType::flow;
  out_pressure.node = 4;  // node 14
  out_pressure.type = BoundaryType::pressure;
  net.boundaries = {in, out_pressure};
  const std::string text = export_text("boundaries.vtp", [&](OutputStream& out) { write_vtk(net, out); });
  const XmlElement file = XmlParser(text).document();
  const XmlElement& piece = file.child("PolyData").child("Piece");
  const XmlElement& points = piece.child("PointData");
  ASSERT_EQ(points.children.size(), 1u);
  EXPECT_EQ(points.children[0].attributes.at("Name"), "boundary");
  EXPECT_EQ(numbers(points.children[0].text), (std::vector<double>{-1, -1, 0, -1, 1}));
  const XmlElement& cells = piece.child("CellData");
  bool found = false;
  for (const XmlElement& array : cells.children)
    if (array.attributes.at("Name") == "distal_diameter") {
      found = true;
      const auto values = numbers(array.text);
      ASSERT_EQ(values.size(), 4u);
      expect_close(1.0e-3, values[0], "tapered");
      expect_close(net.diameter[1], values[1], "untapered: its diameter");
      expect_close(4.0e-5, values[2], "tapered");
    }
  EXPECT_TRUE(found);
}

TEST(ExportVtk, WithoutCoordinatesIsAnInputErrorAndLeavesNoFile) {
  const auto path = scratch_dir() / "no_coordinates.vtp";
  std::filesystem::remove(path);
  {
    OutputStream out(path.string());
    try {
      write_vtk(sample_network(false), out);
      FAIL() << "expected InputError";
    } catch (const InputError& e) {
      EXPECT_STREQ(e.what(), "VTK export needs node coordinates; this network has none");
    }
  }
  EXPECT_FALSE(std::filesystem::exists(path));
}

TEST(ExportVtk, ExtraFieldOfTheWrongLengthIsAnInputError) {
  OutputStream out((scratch_dir() / "short_field.vtp").string());
  const std::vector<double> too_short = {1.0, 2.0};
  EXPECT_THROW(write_vtk(sample_network(), out, {CellField{"flow", too_short}}), InputError);
}

TEST(ExportVtk, FieldNamesAreEscaped) {
  const std::vector<double> values(4, 1.0);
  const std::string text = export_text("escaped.vtp", [&](OutputStream& out) {
    write_vtk(sample_network(), out, {CellField{"a<b & \"c\"", values}});
  });
  const XmlElement file = XmlParser(text).document();
  EXPECT_EQ(
      file.child("PolyData").child("Piece").child("CellData").children.back().attributes.at("Name"),
      "a&lt;b &amp; &quot;c&quot;");
}

// A result undefined in some vessels (a pulse wave speed where no forward wave is
// measurable) is written as "nan", which ParaView's ASCII reader takes (5.11, checked), and
// the other values are unaffected. It was a "non-finite number" internal error before.
TEST(ExportVtk, UndefinedResultsAreWrittenAsNan) {
  const std::vector<double> values = {1.5, std::nan(""), 2.5, INFINITY};
  const std::string text = export_text("nan.vtp", [&](OutputStream& out) {
    write_vtk(sample_network(), out, {CellField{"pwv", values}});
  });
  const XmlElement file = XmlParser(text).document();
  const XmlElement& array = file.child("PolyData").child("Piece").child("CellData").children.back();
  std::istringstream numbers(array.text);
  std::vector<std::string> words{std::istream_iterator<std::string>(numbers), {}};
  EXPECT_EQ(words, (std::vector<std::string>{"1.5", "nan", "2.5", "nan"}));
}

// --- GraphML -------------------------------------------------------------------------------

struct NodeProps {
  long id = -1;
  double x = NAN, y = NAN, z = NAN;
};
struct EdgeProps {
  long id = -1;
  double length = NAN, diameter = NAN, wall_thickness = NAN, youngs_modulus = NAN;
  int generation = -1;
  std::string vessel_class;
};
using ReadGraph =
    boost::adjacency_list<boost::vecS, boost::vecS, boost::directedS, NodeProps, EdgeProps>;

TEST(ExportGraphml, ReadsBackWithBoostWithEveryProperty) {
  const Network net = sample_network();
  const std::string text =
      export_text("sample.graphml", [&](OutputStream& out) { write_graphml(net, out); });

  ReadGraph g;
  boost::dynamic_properties dp;
  dp.property("id", boost::get(&NodeProps::id, g));
  dp.property("x", boost::get(&NodeProps::x, g));
  dp.property("y", boost::get(&NodeProps::y, g));
  dp.property("z", boost::get(&NodeProps::z, g));
  dp.property("id", boost::get(&EdgeProps::id, g));
  dp.property("length", boost::get(&EdgeProps::length, g));
  dp.property("diameter", boost::get(&EdgeProps::diameter, g));
  dp.property("wall_thickness", boost::get(&EdgeProps::wall_thickness, g));
  dp.property("youngs_modulus", boost::get(&EdgeProps::youngs_modulus, g));
  dp.property("generation", boost::get(&EdgeProps::generation, g));
  dp.property("class", boost::get(&EdgeProps::vessel_class, g));
  std::istringstream in(text);
  boost::read_graphml(in, g, dp);

  ASSERT_EQ(boost::num_vertices(g), net.node_count());
  ASSERT_EQ(boost::num_edges(g), net.vessel_count());
  for (std::size_t n = 0; n < net.node_count(); ++n) {
    EXPECT_EQ(g[n].id, net.node_id[n]);
    expect_close(net.x[n], g[n].x, "x");
    expect_close(net.y[n], g[n].y, "y");
    expect_close(net.z[n], g[n].z, "z");
  }
  std::vector<int> seen(net.vessel_count(), 0);
  for (auto [e, end] = boost::edges(g); e != end; ++e) {
    const EdgeProps& p = g[*e];
    const auto v = static_cast<std::size_t>(p.id - 100);
    ASSERT_LT(v, net.vessel_count());
    ++seen[v];
    EXPECT_EQ(boost::source(*e, g), static_cast<std::size_t>(net.from[v])) << p.id;
    EXPECT_EQ(boost::target(*e, g), static_cast<std::size_t>(net.to[v])) << p.id;
    expect_close(net.length[v], p.length, "length");
    expect_close(net.diameter[v], p.diameter, "diameter");
    expect_close(net.wall_thickness[v], p.wall_thickness, "wall_thickness");
    expect_close(net.youngs_modulus[v], p.youngs_modulus, "youngs_modulus");
    EXPECT_EQ(p.generation, net.generation[v]);
    EXPECT_EQ(p.vessel_class, to_string(net.vessel_class[v]));
  }
  EXPECT_EQ(seen, std::vector<int>(net.vessel_count(), 1));
  // Typed keys let graph tools read numbers as numbers.
  EXPECT_NE(text.find("attr.name=\"diameter\" attr.type=\"double\""), std::string::npos);
  EXPECT_NE(text.find("attr.name=\"generation\" attr.type=\"int\""), std::string::npos);
  EXPECT_NE(text.find("attr.name=\"class\" attr.type=\"string\""), std::string::npos);
}

TEST(ExportGraphml, WithoutCoordinatesHasNoCoordinateKeys) {
  const std::string text = export_text(
      "plain.graphml", [](OutputStream& out) { write_graphml(sample_network(false), out); });
  EXPECT_EQ(text.find("attr.name=\"x\""), std::string::npos);
  EXPECT_NE(text.find("attr.name=\"diameter\""), std::string::npos);
}

// --- dot -----------------------------------------------------------------------------------

// The attributes of the edge line "from->to [k=v, ...];", quotes removed.
std::map<std::string, std::string> dot_edge_attributes(const std::string& text,
                                                       const std::string& edge) {
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind(edge + " ", 0) != 0) continue;
    const auto open = line.find('['), close = line.rfind(']');
    EXPECT_NE(open, std::string::npos);
    EXPECT_NE(close, std::string::npos);
    std::map<std::string, std::string> attributes;
    std::istringstream items(line.substr(open + 1, close - open - 1));
    for (std::string item; std::getline(items, item, ',');) {
      const auto start = item.find_first_not_of(' ');
      const auto eq = item.find('=');
      std::string value = item.substr(eq + 1);
      if (value.size() >= 2 && value.front() == '"') value = value.substr(1, value.size() - 2);
      attributes[item.substr(start, eq - start)] = value;
    }
    return attributes;
  }
  ADD_FAILURE() << "no edge " << edge << " in:\n" << text;
  return {};
}

TEST(ExportDot, HasEveryEdgeByNodeIdWithItsAttributes) {
  const Network net = sample_network();
  const std::string text =
      export_text("sample.dot", [&](OutputStream& out) { write_dot(net, out); });
  EXPECT_EQ(text.rfind("digraph G {\n", 0), 0u);
  EXPECT_EQ(text.substr(text.size() - 2), "}\n");
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    const std::string edge =
        std::to_string(net.node_id[net.from[v]]) + "->" + std::to_string(net.node_id[net.to[v]]);
    auto a = dot_edge_attributes(text, edge);
    EXPECT_EQ(a["id"], std::to_string(net.id[v])) << edge;
    EXPECT_EQ(a["class"], to_string(net.vessel_class[v])) << edge;
    EXPECT_EQ(a["generation"], std::to_string(net.generation[v])) << edge;
    expect_close(net.length[v], std::stod(a["length"]), edge + " length");
    expect_close(net.diameter[v], std::stod(a["diameter"]), edge + " diameter");
    expect_close(net.wall_thickness[v], std::stod(a["wall_thickness"]), edge + " wall_thickness");
    expect_close(net.youngs_modulus[v], std::stod(a["youngs_modulus"]), edge + " youngs_modulus");
  }
  // Vertices are named by node id and carry their position.
  EXPECT_NE(text.find("\n12 [x=0, y=0, z=0];\n"), std::string::npos);
}

// --- CSV -----------------------------------------------------------------------------------

TEST(ExportCsv, HeaderAndRowsAreExact) {
  const std::string text =
      export_text("sample.csv", [](OutputStream& out) { write_csv(sample_network(), out); });
  EXPECT_EQ(text,
            "id,from,to,length_m,diameter_m,wall_thickness_m,youngs_modulus_pa,generation,class\n"
            "100,12,10,0.0123456789,0.00123456789,0.00015,1000000,0,artery\n"
            "101,10,11,0.0031,0.0004,6e-05,250000,1,small_artery\n"
            "102,10,13,0.0032,5e-05,1e-05,250000,1,arteriole\n"
            "103,11,14,0.0021,8e-06,1e-06,125000,2,capillary\n");
}

// --- Format names and dispatch -------------------------------------------------------------

TEST(ExportFormats, NamesRoundTrip) {
  for (auto format : {ExportFormat::json, ExportFormat::vtk, ExportFormat::graphml,
                      ExportFormat::dot, ExportFormat::csv}) {
    EXPECT_EQ(parse_export_format(to_string(format)), format);
  }
  EXPECT_EQ(to_string(ExportFormat::graphml), "graphml");
  EXPECT_FALSE(parse_export_format("VTK").has_value());
  EXPECT_FALSE(parse_export_format("xml").has_value());
  EXPECT_FALSE(parse_export_format("").has_value());
}

TEST(ExportFormats, DispatchWritesTheSameAsTheDirectWriter) {
  // json (write_network) is the native writer's business and is tested with it.
  const Network net = sample_network();
  const std::pair<ExportFormat, void (*)(const Network&, OutputStream&)> cases[] = {
      {ExportFormat::vtk, [](const Network& n, OutputStream& o) { write_vtk(n, o); }},
      {ExportFormat::graphml, write_graphml},
      {ExportFormat::dot, write_dot},
      {ExportFormat::csv, write_csv},
  };
  for (const auto& c : cases) {
    const std::string name(to_string(c.first));
    EXPECT_EQ(export_text("dispatch." + name,
                          [&](OutputStream& o) { write_network_as(net, c.first, o); }),
              export_text("direct." + name, [&](OutputStream& o) { c.second(net, o); }))
        << name;
  }
}

}  // namespace
}  // namespace hemotree
