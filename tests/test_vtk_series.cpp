// VTK time series read back: the .pvd collection and every .vtp frame go through a small
// XML reader and their numbers are compared with what was written.
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <unistd.h>

#include "core/errors.hpp"
#include "formats/vtk_series.hpp"
#include "tests/xml_reader.hpp"

namespace hemotree {
namespace {

namespace fs = std::filesystem;
using test_xml::XmlElement;
using test_xml::XmlParser;

// A root splitting into two, one of which splits again: 4 vessels on 5 nodes.
Network sample_network(bool with_coordinates = true) {
  Network net;
  auto node = [&](std::int64_t id, double x, double y, double z) {
    return with_coordinates ? net.add_node(id, x, y, z) : net.add_node(id);
  };
  const auto root = node(20, 0.0, 0.0, 0.0);
  const auto a = node(21, 0.0, 0.0, 0.012);
  const auto b = node(22, 0.001, 0.0, 0.015);
  const auto c = node(23, -0.001, 0.0, 0.015);
  const auto d = node(24, 0.0015, -2.5e-4, 0.017);
  net.add_vessel(200, root, a, 0.012, 1.23456789e-3, 1.5e-4, 1e6, 0);
  net.add_vessel(201, a, b, 0.0031, 4.0e-4, 6.0e-5, 2.5e5, 1);
  net.add_vessel(202, a, c, 0.0032, 5.0e-5, 1.0e-5, 2.5e5, 1);
  net.add_vessel(203, b, d, 0.0021, 8.0e-6, 1.0e-6, 1.25e5, 2);
  return net;
}

// A fresh directory per test, removed with everything in it afterwards.
class ScratchDir {
 public:
  ScratchDir() {
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() / ("hemotree_vtk_series_" + std::to_string(::getpid()) +
                                         "_" + test->test_suite_name() + "_" + test->name());
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path.string());
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::vector<double> numbers(const std::string& text) {
  std::istringstream in(text);
  std::vector<double> values;
  for (double v; in >> v;) values.push_back(v);
  EXPECT_TRUE(in.eof()) << "not a number in: " << text.substr(0, 80);
  return values;
}

void expect_values(const std::vector<double>& expected, const std::vector<double>& actual,
                   const std::string& what) {
  ASSERT_EQ(expected.size(), actual.size()) << what;
  for (std::size_t i = 0; i < expected.size(); ++i)
    EXPECT_NEAR(expected[i], actual[i], 1e-8 * std::abs(expected[i])) << what << '[' << i << ']';
}

XmlElement read_xml(const fs::path& path) { return XmlParser(read_text(path)).document(); }

// Pressure, flow and area of one frame: every value differs between vessels and frames,
// and carries 9 significant digits so that a lost digit shows.
struct FrameFields {
  std::vector<double> p, Q, A;
  explicit FrameFields(int frame) {
    for (int v = 0; v < 4; ++v) {
      p.push_back(13332.2368 + 101.123456 * frame - 7.01234567 * v);
      Q.push_back((1.23456789e-6 - 2.0e-7 * v) * (1.0 + 0.25 * frame));
      A.push_back(1.19695154e-6 / (1 + v) * (1.0 + 0.01 * frame));
    }
  }
  std::vector<CellField> cell_fields() const { return {{"p", p}, {"Q", Q}, {"A", A}}; }
};

// --- Tests -----------------------------------------------------------------------------------

TEST(VtkTimeSeries, FramesAndCollectionReadBackWithTheirNumbers) {
  const ScratchDir dir;
  const Network net = sample_network();
  // The last time needs 9 digits: 6 would merge it with a neighbour in a fine series.
  const std::vector<double> times = {0.0, 0.00125, 0.123456789};
  std::vector<FrameFields> written;

  VtkTimeSeries series(net, dir.path(), "flow");
  for (std::size_t k = 0; k < times.size(); ++k) {
    written.emplace_back(static_cast<int>(k));
    series.add_frame(times[k], written.back().cell_fields());
    EXPECT_EQ(series.frames(), k + 1);
  }
  EXPECT_FALSE(fs::exists(dir.path() / "flow.pvd")) << "a collection before finish()";
  series.finish();
  EXPECT_EQ(series.collection_path(), dir.path() / "flow.pvd");

  const XmlElement collection_file = read_xml(dir.path() / "flow.pvd");
  EXPECT_EQ(collection_file.name, "VTKFile");
  EXPECT_EQ(collection_file.attributes.at("type"), "Collection");
  EXPECT_EQ(collection_file.attributes.at("version"), "0.1");
  EXPECT_EQ(collection_file.attributes.at("byte_order"), "LittleEndian");
  const XmlElement& collection = collection_file.child("Collection");
  ASSERT_EQ(collection.children.size(), times.size());

  for (std::size_t k = 0; k < times.size(); ++k) {
    const XmlElement& dataset = collection.children[k];
    EXPECT_EQ(dataset.name, "DataSet");
    EXPECT_NEAR(std::stod(dataset.attributes.at("timestep")), times[k], 1e-8 * times[k]);
    EXPECT_EQ(dataset.attributes.at("group"), "");
    EXPECT_EQ(dataset.attributes.at("part"), "0");
    const std::string file = dataset.attributes.at("file");
    EXPECT_EQ(file, "flow_000" + std::to_string(k) + ".vtp");
    EXPECT_EQ(file, series.frame_file_name(k));
    // Relative to the .pvd, so the directory can be moved as a whole.
    ASSERT_TRUE(fs::path(file).is_relative());
    ASSERT_TRUE(fs::exists(dir.path() / file)) << file;

    const XmlElement vtp = read_xml(dir.path() / file);
    EXPECT_EQ(vtp.attributes.at("type"), "PolyData");
    const XmlElement& piece = vtp.child("PolyData").child("Piece");
    // PolyData counts its cells by kind; every vessel is a line cell.
    EXPECT_EQ(std::stoul(piece.attributes.at("NumberOfLines")), net.vessel_count());
    EXPECT_EQ(std::stoul(piece.attributes.at("NumberOfPoints")), net.node_count());
    EXPECT_EQ(numbers(piece.child("Points").child("DataArray").text).size(),
              3 * net.node_count());

    const XmlElement& cells = piece.child("CellData");
    const std::string where = file + " ";
    expect_values(written[k].p, numbers(cells.data_array("p").text), where + "p");
    expect_values(written[k].Q, numbers(cells.data_array("Q").text), where + "Q");
    expect_values(written[k].A, numbers(cells.data_array("A").text), where + "A");
    expect_values(net.diameter, numbers(cells.data_array("diameter").text), where + "diameter");
    const std::vector<double> ids(net.id.begin(), net.id.end());
    expect_values(ids, numbers(cells.data_array("id").text), where + "id");
  }
  // Nothing else: no temporary files left behind, no stray frames.
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()),
            static_cast<std::ptrdiff_t>(times.size() + 1));
}

TEST(VtkTimeSeries, NoCollectionUntilFinishEvenFromAnEarlierRun) {
  const ScratchDir dir;
  const Network net = sample_network();
  {
    VtkTimeSeries first(net, dir.path(), "run");
    first.add_frame(0.0, FrameFields(0).cell_fields());
    first.finish();
  }
  ASSERT_TRUE(fs::exists(dir.path() / "run.pvd"));
  // A rerun overwrites the frames one by one: the old collection must not survive to list
  // them as if they were one complete series.
  VtkTimeSeries second(net, dir.path(), "run");
  EXPECT_FALSE(fs::exists(dir.path() / "run.pvd"));
  second.add_frame(0.5, FrameFields(1).cell_fields());
  EXPECT_FALSE(fs::exists(dir.path() / "run.pvd"));
}

TEST(VtkTimeSeries, EmptySeriesFinishesAsAnEmptyCollection) {
  const ScratchDir dir;
  const Network net = sample_network();
  VtkTimeSeries series(net, dir.path(), "none");
  series.finish();
  const XmlElement file = read_xml(dir.path() / "none.pvd");
  EXPECT_TRUE(file.child("Collection").children.empty());
}

TEST(VtkTimeSeries, WithoutCoordinatesIsAnInputError) {
  const ScratchDir dir;
  const Network net = sample_network(false);
  EXPECT_THROW(VtkTimeSeries(net, dir.path(), "flow"), InputError);
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

TEST(VtkTimeSeries, StemMustBeAPlainFileName) {
  const ScratchDir dir;
  const Network net = sample_network();
  EXPECT_THROW(VtkTimeSeries(net, dir.path(), ""), InputError);
  EXPECT_THROW(VtkTimeSeries(net, dir.path(), "sub/flow"), InputError);
}

TEST(VtkTimeSeries, MissingDirectoryIsAnIoError) {
  const ScratchDir dir;
  const Network net = sample_network();
  VtkTimeSeries series(net, dir.path() / "missing", "flow");
  EXPECT_THROW(series.add_frame(0.0, FrameFields(0).cell_fields()), IoError);
  EXPECT_EQ(series.frames(), 0u);
  EXPECT_THROW(series.finish(), IoError);
  EXPECT_FALSE(fs::exists(dir.path() / "missing"));
}

TEST(VtkTimeSeries, BadFrameIsAnInputErrorAndIsNotCounted) {
  const ScratchDir dir;
  const Network net = sample_network();
  VtkTimeSeries series(net, dir.path(), "flow");
  const std::vector<double> too_short = {1.0, 2.0};
  EXPECT_THROW(series.add_frame(0.0, {CellField{"p", too_short}}), InputError);
  EXPECT_EQ(series.frames(), 0u);
  EXPECT_TRUE(fs::is_empty(dir.path())) << "a partial frame was left behind";

  series.add_frame(1.0, FrameFields(0).cell_fields());
  EXPECT_TRUE(fs::exists(dir.path() / "flow_0000.vtp")) << "the failed frame's index is reused";
  // ParaView orders frames by time: a repeat, an earlier time, one equal at 9 digits, or a
  // non-finite one would hide or reorder frames.
  EXPECT_THROW(series.add_frame(1.0, FrameFields(1).cell_fields()), InputError);
  EXPECT_THROW(series.add_frame(0.5, FrameFields(1).cell_fields()), InputError);
  EXPECT_THROW(series.add_frame(1.0 + 1e-12, FrameFields(1).cell_fields()), InputError);
  EXPECT_THROW(series.add_frame(std::nan(""), FrameFields(1).cell_fields()), InputError);
  EXPECT_EQ(series.frames(), 1u);
  series.add_frame(1.00000001, FrameFields(1).cell_fields());
  EXPECT_EQ(series.frames(), 2u);
}

TEST(VtkTimeSeries, NoFramesAfterFinish) {
  const ScratchDir dir;
  const Network net = sample_network();
  VtkTimeSeries series(net, dir.path(), "flow");
  series.add_frame(0.0, FrameFields(0).cell_fields());
  series.finish();
  EXPECT_THROW(series.add_frame(1.0, FrameFields(1).cell_fields()), std::logic_error);
}

TEST(VtkTimeSeries, FrameNamesArePaddedToFourDigitsAndGrowBeyond) {
  const ScratchDir dir;
  const Network net = sample_network();
  const VtkTimeSeries series(net, dir.path(), "s");
  EXPECT_EQ(series.frame_file_name(0), "s_0000.vtp");
  EXPECT_EQ(series.frame_file_name(42), "s_0042.vtp");
  EXPECT_EQ(series.frame_file_name(9999), "s_9999.vtp");
  EXPECT_EQ(series.frame_file_name(12345), "s_12345.vtp");
}

TEST(VtkTimeSeries, StemIsEscapedInTheCollection) {
  const ScratchDir dir;
  const Network net = sample_network();
  VtkTimeSeries series(net, dir.path(), "a&\"b");
  series.add_frame(0.0, FrameFields(0).cell_fields());
  series.finish();
  EXPECT_TRUE(fs::exists(dir.path() / "a&\"b_0000.vtp"));
  const XmlElement file = read_xml(dir.path() / "a&\"b.pvd");
  EXPECT_EQ(file.child("Collection").child("DataSet").attributes.at("file"),
            "a&amp;&quot;b_0000.vtp");
}

}  // namespace
}  // namespace hemotree
