// read_vtk_centerline: one Y-shaped centerline written by the test in every encoding VTK
// uses (XML ascii, inline base64 with and without zlib, appended raw, appended base64 with
// zlib as VTK writes by default, legacy ASCII in both cell layouts), each read back to the
// same three vessels; then the ways a file can be wrong, each with its message.
#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "cli/setting_words.hpp"
#include "core/errors.hpp"
#include "core/setting_error.hpp"
#include "exchange/vtk_centerline.hpp"
#include "scratch_path.hpp"

namespace hemotree {
namespace {

// The Y, in mm: a trunk P0 (0,0,0) - P1 (0,0,3) - P2 (0,0,5), the junction; branch A P2 -
// P3 (3,0,9) - P4 (3,0,13); branch B P2 - P5 (-6,0,13). Segment lengths 3, 2 | 5, 4 | 10.
// The length-weighted mean radius (trapezoidal along each segment):
//   trunk (3 (1 + 1)/2 + 2 (1 + 0.8)/2) / 5 = 0.96
//   A     (5 (0.8 + 0.6)/2 + 4 (0.6 + 0.6)/2) / 9 = 5.9 / 9
//   B     (10 (0.8 + 0.5)/2) / 10 = 0.65
struct Geometry {
  std::vector<double> xyz, radius;
  std::vector<double> connectivity, offsets;  // offsets: the end of each cell, as VTK XML
};

Geometry y_shape() {
  return {{0, 0, 0, 0, 0, 3, 0, 0, 5, 3, 0, 9, 3, 0, 13, -6, 0, 13},
          {1.0, 1.0, 0.8, 0.6, 0.6, 0.5},
          {0, 1, 2, 2, 3, 4, 2, 5},
          {3, 6, 8}};
}

// The same Y with polylines that do not share the junction's id, only its coordinates.
Geometry y_shape_unshared() {
  return {{0, 0, 0, 0, 0, 3, 0, 0, 5, 0, 0, 5, 3, 0, 9, 3, 0, 13, 0, 0, 5, -6, 0, 13},
          {1.0, 1.0, 0.8, 0.8, 0.6, 0.6, 0.8, 0.5},
          {0, 1, 2, 3, 4, 5, 6, 7},
          {3, 6, 8}};
}

// --- writing VTK the way VTK does ---------------------------------------------------------

std::string base64(const std::string& bytes) {
  static const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
    std::uint32_t bits = 0;
    for (std::size_t k = 0; k < 3; ++k)
      bits = (bits << 8) | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0u);
    for (std::size_t k = 0; k < 4; ++k) out += k <= n ? digits[(bits >> (18 - 6 * k)) & 63] : '=';
  }
  return out;
}

struct Array {
  std::string name, type;
  int components;
  std::vector<double> values;
};

std::string raw_bytes(const Array& a) {
  std::string out;
  auto put = [&out](const auto v) { out.append(reinterpret_cast<const char*>(&v), sizeof v); };
  for (double v : a.values) {
    if (a.type == "Float64") put(v);
    else if (a.type == "Float32") put(static_cast<float>(v));
    else if (a.type == "Int64") put(static_cast<std::int64_t>(v));
    else if (a.type == "Int32") put(static_cast<std::int32_t>(v));
    else put(static_cast<std::uint8_t>(v));
  }
  return out;
}

enum class Mode { ascii, binary, binary_zlib, appended_raw, appended_base64_zlib };

struct Layout {
  Mode mode = Mode::ascii;
  bool header64 = false;  // header_type UInt64
  std::size_t block_size = 40;  // small: several zlib blocks and a partial last one
};

std::string word(std::uint64_t v, bool header64) {
  std::string out(header64 ? 8 : 4, '\0');
  std::memcpy(out.data(), &v, out.size());  // little-endian machine
  return out;
}

// The array's header and data bytes: [size] data, or VTK's zlib blocks.
std::pair<std::string, std::string> payload(const Array& a, const Layout& layout, bool zlib) {
  const std::string bytes = raw_bytes(a);
  if (!zlib) return {word(bytes.size(), layout.header64), bytes};
  const std::size_t bs = layout.block_size;
  const std::size_t blocks = (bytes.size() + bs - 1) / bs;
  std::string header = word(blocks, layout.header64) + word(bs, layout.header64) +
                       word(bytes.size() % bs, layout.header64), data;
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::string block = bytes.substr(b * bs, bs);
    uLongf size = compressBound(block.size());
    std::string packed(size, '\0');
    EXPECT_EQ(compress(reinterpret_cast<Bytef*>(packed.data()), &size, reinterpret_cast<const Bytef*>(block.data()),
                       block.size()), Z_OK);
    packed.resize(size);
    header += word(size, layout.header64);
    data += packed;
  }
  return {header, data};
}

class VtpWriter {
 public:
  explicit VtpWriter(Layout layout) : layout_(layout) {}

  std::string data_array(const Array& a) {
    std::string e = "<DataArray type=\"" + a.type + "\" Name=\"" + a.name + "\" NumberOfComponents=\"" +
                    std::to_string(a.components) + "\" format=\"";
    const bool zlib = layout_.mode == Mode::binary_zlib || layout_.mode == Mode::appended_base64_zlib;
    switch (layout_.mode) {
      case Mode::ascii: {
        std::ostringstream text;
        text.precision(17);
        for (double v : a.values) text << v << ' ';
        return e + "ascii\">\n" + text.str() + "\n</DataArray>\n";
      }
      case Mode::binary:  // header and data as one base64 text
      case Mode::binary_zlib: {
        const auto [header, data] = payload(a, layout_, zlib);
        // VTK encodes a compressed array's header and blocks as two base64 texts.
        return e + "binary\">" + (zlib ? base64(header) + base64(data) : base64(header + data)) + "</DataArray>\n";
      }
      case Mode::appended_raw:
      case Mode::appended_base64_zlib: {
        const auto [header, data] = payload(a, layout_, zlib);
        const std::size_t offset = appended_.size();
        appended_ += layout_.mode == Mode::appended_raw ? header + data : base64(header) + base64(data);
        return e + "appended\" offset=\"" + std::to_string(offset) + "\"/>\n";
      }
    }
    return e;
  }

  std::string file(const Geometry& g, const std::string& point_type = "Float64",
                   const std::string& radius_name = "MaximumInscribedSphereRadius") {
    const std::size_t points = g.radius.size(), lines = g.offsets.size();
    std::string body = "<PolyData>\n<Piece NumberOfPoints=\"" + std::to_string(points) +
                       "\" NumberOfVerts=\"0\" NumberOfLines=\"" + std::to_string(lines) +
                       "\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n";
    body += "<PointData Scalars=\"" + radius_name + "\">\n" + data_array({radius_name, "Float64", 1, g.radius}) +
            "</PointData>\n";
    std::vector<double> ids(lines);
    for (std::size_t k = 0; k < lines; ++k) ids[k] = static_cast<double>(k);
    body += "<CellData>\n" + data_array({"CenterlineIds", "Int32", 1, ids}) + "</CellData>\n";
    body += "<Points>\n" + data_array({"Points", point_type, 3, g.xyz}) + "</Points>\n";
    body += "<Lines>\n" + data_array({"connectivity", "Int64", 1, g.connectivity}) +
            data_array({"offsets", "Int64", 1, g.offsets}) + "</Lines>\n";
    body += "</Piece>\n</PolyData>\n";
    std::string head = "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"";
    head += layout_.header64 ? "UInt64\"" : "UInt32\"";
    if (layout_.mode == Mode::binary_zlib || layout_.mode == Mode::appended_base64_zlib)
      head += " compressor=\"vtkZLibDataCompressor\"";
    head += ">\n";
    std::string tail;
    if (!appended_.empty())
      tail = std::string("<AppendedData encoding=\"") + (layout_.mode == Mode::appended_raw ? "raw" : "base64") +
             "\">\n   _" + appended_ + "\n</AppendedData>\n";
    return head + body + tail + "</VTKFile>\n";
  }

 private:
  Layout layout_;
  std::string appended_;
};

std::string legacy_classic(const Geometry& g) {
  std::ostringstream f;
  f.precision(17);
  f << "# vtk DataFile Version 3.0\nY centerline\nASCII\nDATASET POLYDATA\n";
  f << "POINTS " << g.radius.size() << " double\n";
  for (double v : g.xyz) f << v << ' ';
  f << "\nLINES " << g.offsets.size() << ' ' << g.offsets.size() + g.connectivity.size() << '\n';
  double begin = 0;
  for (double end : g.offsets) {
    f << end - begin;
    for (auto k = static_cast<std::size_t>(begin); k < static_cast<std::size_t>(end); ++k) f << ' ' << g.connectivity[k];
    f << '\n';
    begin = end;
  }
  f << "CELL_DATA " << g.offsets.size() << "\nSCALARS CenterlineIds int 1\nLOOKUP_TABLE default\n0 1 2\n";
  f << "POINT_DATA " << g.radius.size() << "\nNORMALS FrenetNormal double\n";
  for (std::size_t k = 0; k < 3 * g.radius.size(); ++k) f << "0 ";
  f << "\nSCALARS MaximumInscribedSphereRadius double\nLOOKUP_TABLE default\n";
  for (double r : g.radius) f << r << ' ';
  f << '\n';
  return f.str();
}

// VTK 9's legacy writer: OFFSETS and CONNECTIVITY, arrays as FIELD data, METADATA blocks.
std::string legacy_51(const Geometry& g) {
  std::ostringstream f;
  f.precision(17);
  f << "# vtk DataFile Version 5.1\nvtk output\nASCII\nDATASET POLYDATA\n";
  f << "POINTS " << g.radius.size() << " float\n";
  for (double v : g.xyz) f << v << ' ';
  f << "\nMETADATA\nINFORMATION 0\n\n";
  f << "LINES " << g.offsets.size() + 1 << ' ' << g.connectivity.size() << "\nOFFSETS vtktypeint64\n0";
  for (double o : g.offsets) f << ' ' << o;
  f << "\nCONNECTIVITY vtktypeint64\n";
  for (double id : g.connectivity) f << id << ' ';
  f << "\nPOINT_DATA " << g.radius.size() << "\nFIELD FieldData 2\nAbscissas 1 " << g.radius.size() << " double\n";
  for (std::size_t k = 0; k < g.radius.size(); ++k) f << k << ' ';
  f << "\nMETADATA\nINFORMATION 1\nNAME L2_NORM_RANGE LOCATION vtkDataArray\nDATA 2 0 5\n\n";
  f << "MaximumInscribedSphereRadius 1 " << g.radius.size() << " double\n";
  for (double r : g.radius) f << r << ' ';
  f << '\n';
  return f.str();
}

// --- reading -------------------------------------------------------------------------------

class ImportVtk : public ::testing::Test {
 protected:
  std::string write(const std::string& name, const std::string& text) {
    const auto path = scratch_path(name).string();
    std::ofstream(path, std::ios::binary) << text;
    return path;
  }
  Network read(const std::string& name, const std::string& text, double unit = 1e-3) {
    notes.clear();
    ImportOptions options;
    options.note = [this](const std::string& line) { notes.push_back(line); };
    CenterlineOptions c;
    c.length_unit = unit;
    return read_vtk_centerline(write(name, text), options, c);
  }
  std::string message(const std::string& name, const std::string& text) {
    try {
      read(name, text);
    } catch (const InputError& e) {
      // As vimport shows it: a setting the message names, in its flag's words.
      const auto* setting = dynamic_cast<const SettingError*>(&e);
      const std::string m = setting ? setting->in_words(vimport_words()) : e.what();
      const std::string path = scratch_path(name).string();
      return m.rfind(path, 0) == 0 ? m.substr(path.size()) : m;  // without the file's name
    }
    return "no error";
  }
  bool noted(const std::string& part) const {
    for (const auto& n : notes)
      if (n.find(part) != std::string::npos) return true;
    return false;
  }
  std::vector<std::string> notes;
};

// The three vessels of the Y, in mm, to the given relative tolerance.
void expect_y(const Network& net, double tol, std::int64_t junction_id = 2, std::int64_t end_a = 4,
              std::int64_t end_b = 5) {
  ASSERT_EQ(net.vessel_count(), 3u);
  ASSERT_EQ(net.node_count(), 4u);
  const double length[3] = {5e-3, 9e-3, 10e-3};
  const double diameter[3] = {2 * 0.96e-3, 2 * 5.9e-3 / 9, 2 * 0.65e-3};
  const std::int64_t from[3] = {0, junction_id, junction_id}, to[3] = {junction_id, end_a, end_b};
  for (std::size_t v = 0; v < 3; ++v) {
    EXPECT_EQ(net.id[v], static_cast<std::int64_t>(v));
    EXPECT_NEAR(net.length[v], length[v], tol * length[v]) << "vessel " << v;
    EXPECT_NEAR(net.diameter[v], diameter[v], tol * diameter[v]) << "vessel " << v;
    EXPECT_EQ(net.node_id[static_cast<std::size_t>(net.from[v])], from[v]) << "vessel " << v;
    EXPECT_EQ(net.node_id[static_cast<std::size_t>(net.to[v])], to[v]) << "vessel " << v;
    EXPECT_TRUE(std::isfinite(net.wall_thickness[v]) && std::isfinite(net.youngs_modulus[v]));
  }
  EXPECT_EQ(net.generation, (std::vector<std::int32_t>{0, 1, 1}));
  ASSERT_TRUE(net.has_coordinates());
  const auto junction = static_cast<std::size_t>(net.from[1]);
  EXPECT_NEAR(net.z[junction], 5e-3, 1e-15);
  const auto tip_b = static_cast<std::size_t>(net.to[2]);
  EXPECT_NEAR(net.x[tip_b], -6e-3, 1e-15);
  EXPECT_NEAR(net.z[tip_b], 13e-3, 1e-15);
}

TEST_F(ImportVtk, AsciiXml) {
  expect_y(read("ascii.vtp", VtpWriter({Mode::ascii}).file(y_shape())), 1e-14);
  EXPECT_TRUE(noted("cell data not imported: CenterlineIds"));
  EXPECT_TRUE(noted("in units of 0.001 m"));
}

TEST_F(ImportVtk, InlineBase64WithUInt32Header) {
  expect_y(read("binary.vtp", VtpWriter({Mode::binary}).file(y_shape())), 1e-14);
}

TEST_F(ImportVtk, InlineBase64ZlibWithUInt64Header) {
  expect_y(read("zlib.vtp", VtpWriter({Mode::binary_zlib, true}).file(y_shape())), 1e-14);
}

TEST_F(ImportVtk, ZlibInOneBlockAndInExactBlocks) {
  // 8 points x 3 x 8 bytes = 192 bytes: one block of 4096; blocks of 48 end with a full one.
  expect_y(read("zlib1.vtp", VtpWriter({Mode::binary_zlib, false, 4096}).file(y_shape())), 1e-14);
  expect_y(read("zlib48.vtp", VtpWriter({Mode::binary_zlib, false, 48}).file(y_shape())), 1e-14);
}

TEST_F(ImportVtk, AppendedRaw) {
  expect_y(read("raw.vtp", VtpWriter({Mode::appended_raw, true}).file(y_shape())), 1e-14);
}

TEST_F(ImportVtk, AppendedBase64ZlibAsVtkWritesByDefault) {
  expect_y(read("appended.vtp", VtpWriter({Mode::appended_base64_zlib}).file(y_shape())), 1e-14);
  expect_y(read("appended64.vtp", VtpWriter({Mode::appended_base64_zlib, true}).file(y_shape())), 1e-14);
}

TEST_F(ImportVtk, Float32PointsKeepSinglePrecision) {
  // Every coordinate is an integer, exact in float; only the radii are doubles here.
  expect_y(read("float.vtp", VtpWriter({Mode::binary}).file(y_shape(), "Float32")), 1e-14);
}

TEST_F(ImportVtk, LegacyAsciiClassicAndVersion51) {
  expect_y(read("classic.vtk", legacy_classic(y_shape())), 1e-14);
  EXPECT_TRUE(noted("point data not imported: FrenetNormal"));
  expect_y(read("v51.vtk", legacy_51(y_shape())), 1e-14);
  EXPECT_TRUE(noted("point data not imported: Abscissas"));
}

TEST_F(ImportVtk, PolylinesJoinAtCoincidentPoints) {
  // The junction's three copies (points 2, 3, 6) are one node, with the smallest id.
  expect_y(read("unshared.vtp", VtpWriter({Mode::ascii}).file(y_shape_unshared())), 1e-14, 2, 5, 7);
  EXPECT_TRUE(noted("joined 2 points lying on another point"));
}

TEST_F(ImportVtk, OverlappingCenterlinesThroughTheSamePointsMerge) {
  // As vmtkcenterlines' output where the centerlines coincide along the trunk: one polyline
  // from the inlet to each outlet, the trunk's points repeated in each.
  Geometry g{{0, 0, 0, 0, 0, 3, 0, 0, 5, 3, 0, 9, 3, 0, 13, 0, 0, 0, 0, 0, 3, 0, 0, 5, -6, 0, 13},
             {1.0, 1.0, 0.8, 0.6, 0.6, 1.0, 1.0, 0.8, 0.5},
             {0, 1, 2, 3, 4, 5, 6, 7, 8},
             {5, 9}};
  expect_y(read("overlap.vtp", VtpWriter({Mode::ascii}).file(g)), 1e-14, 2, 4, 8);
  EXPECT_TRUE(noted("merged 2 segments that several polylines share"));
}

TEST_F(ImportVtk, UnitDefaultsToMetres) {
  Geometry metres = y_shape();
  for (double& r : metres.radius) r *= 0.01;  // a Y of metres: 5 m long, 2 cm wide
  const Network net = read("metres.vtp", VtpWriter({Mode::ascii}).file(metres), 1.0);
  EXPECT_NEAR(net.length[0], 5.0, 1e-14);
  EXPECT_NEAR(net.diameter[0], 0.0192, 1e-14);
  // A model in mm read as metres: its trunk would be 1.92 m wide.
  const std::string path = write("mm.vtp", VtpWriter({Mode::ascii}).file(y_shape()));
  try {
    read_vtk_centerline(path, ImportOptions{});
    ADD_FAILURE() << "no error";
  } catch (const SettingError& e) {
    EXPECT_EQ(e.setting(), "unit");
    EXPECT_EQ(e.in_words(vimport_words()), path + ": vessel 0 (polyline 0, point 0 to point 2): \"diameter\" must lie in "
                                            "[2e-6, 0.5] m (got 1.92); the file's lengths were read as 1 m each "
                                            "(vimport --unit sets the unit, e.g. --unit mm)");
  }
}

TEST_F(ImportVtk, RefusesSideBySideCenterlines) {
  // Two centerlines from the same inlet point, 0.01 mm apart along a 1 mm radius trunk.
  Geometry g{{0, 0, 0, 0, 0, 3, 0, 0, 5, 3, 0, 9, 0.01, 0, 3, 0.01, 0, 5, -6, 0, 13},
             {1.0, 1.0, 0.8, 0.6, 1.0, 0.8, 0.5},
             {0, 1, 2, 3, 0, 4, 5, 6},
             {4, 8}};
  EXPECT_EQ(message("side.vtp", VtpWriter({Mode::ascii}).file(g)),
            ": polylines 0 and 1 leave point 0 (0, 0, 0) side by side (within 0.05 radii over 2 radii): "
            "overlapping centerlines, as vmtkcenterlines writes one from the inlet to each outlet; split and "
            "merge them first (vmtkbranchextractor, then vmtkcenterlinemerge)");
}

TEST_F(ImportVtk, MissingRadiusNamesTheArrays) {
  EXPECT_EQ(message("noradius.vtp", VtpWriter({Mode::ascii}).file(y_shape(), "Float64", "Radius")),
            ": PolyData/Piece/PointData: no DataArray Name=\"MaximumInscribedSphereRadius\" (point data arrays: "
            "Radius; cell data arrays: CenterlineIds); vimport --radius-array names another");
  std::string legacy = legacy_classic(y_shape());
  legacy.replace(legacy.find("SCALARS Max"), 36, "SCALARS Radius");
  EXPECT_EQ(message("noradius.vtk", legacy),
            ": no point data array \"MaximumInscribedSphereRadius\" (point data arrays: FrenetNormal, Radius; "
            "cell data arrays: CenterlineIds); vimport --radius-array names another");
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

TEST_F(ImportVtk, MalformedXml) {
  const std::string ascii = VtpWriter({Mode::ascii}).file(y_shape());
  EXPECT_EQ(message("a.vtp", replaced(ascii, "0.59999999999999998", "0.6x")),
            ": PolyData/Piece/PointData/DataArray[Name=MaximumInscribedSphereRadius]: '0.6x' is not a number");
  EXPECT_EQ(message("b.vtp", replaced(ascii, "NumberOfPolys=\"0\"", "NumberOfPolys=\"12\"")),
            ": PolyData/Piece: NumberOfPolys=\"12\": a surface, not centerlines (vmtkcenterlines computes them "
            "from a surface)");
  EXPECT_EQ(message("c.vtp", replaced(ascii, "NumberOfPoints=\"6\"", "NumberOfPoints=\"7\"")),
            ": PolyData/Piece/Points/DataArray: holds 18 numbers, expected 21");
  EXPECT_EQ(message("d.vtp", replaced(ascii, "type=\"PolyData\"", "type=\"UnstructuredGrid\"")),
            ": VTKFile: type=\"UnstructuredGrid\": centerlines are PolyData (.vtp); hemotree reads no other VTK "
            "data set");
  EXPECT_EQ(message("e.vtp", replaced(ascii, "<Points>", "<Points")), ":16: not well-formed XML: expected >");
  EXPECT_EQ(message("f.vtp", replaced(ascii, "2 5 \n</DataArray>", "2 9 \n</DataArray>")),
            ": PolyData/Piece/Lines/DataArray[Name=connectivity]: point id 9 outside [0, 6)");
  EXPECT_EQ(message("g.vtp", replaced(ascii, "Name=\"connectivity\" NumberOfComponents=\"1\"",
                                      "Name=\"connectivity\" NumberOfComponents=\"2\"")),
            ": PolyData/Piece/Lines/DataArray[Name=connectivity]: NumberOfComponents=\"2\", expected 1");
  EXPECT_EQ(message("h.vtp", replaced(ascii, "header_type=\"UInt32\"", "compressor=\"vtkLZ4DataCompressor\"")),
            ": VTKFile: compressor=\"vtkLZ4DataCompressor\": hemotree reads zlib-compressed "
            "(vtkZLibDataCompressor) or uncompressed data");
}

TEST_F(ImportVtk, MalformedBinary) {
  const std::string zlib = VtpWriter({Mode::binary_zlib}).file(y_shape());
  // A character that is not base64 in the radius array.
  const auto at = zlib.find("format=\"binary\">") + 20;
  std::string bad = zlib;
  bad[at] = '!';
  EXPECT_EQ(message("a.vtp", bad),
            ": PolyData/Piece/PointData/DataArray[Name=MaximumInscribedSphereRadius]: '!' is not a base64 character");
  // The blocks cut short: seen from the header's sizes, before any block is read.
  std::string cut = zlib;
  const auto end = cut.find("</DataArray>");
  cut.erase(end - 8, 8);
  EXPECT_EQ(message("b.vtp", cut),
            ": PolyData/Piece/PointData/DataArray[Name=MaximumInscribedSphereRadius]: its compressed blocks take "
            "more than the 36 bytes the data hold");
  // A block that is not zlib: the raw file's bytes with the compressor declared.
  const std::string raw = VtpWriter({Mode::appended_raw}).file(y_shape());
  EXPECT_EQ(message("c.vtp", replaced(raw, "header_type=\"UInt32\"", "header_type=\"UInt32\" compressor=\"vtkZLibDataCompressor\"")),
            ": PolyData/Piece/Points/DataArray: its compression header gives 144 blocks of 0 bytes (last 0), "
            "expected 144 bytes in all");
  EXPECT_EQ(message("d.vtp", replaced(raw, "   _", "   ")), ": VTKFile/AppendedData: the data do not begin with '_'");
  EXPECT_EQ(message("e.vtp", replaced(raw, "offset=\"0\"", "offset=\"100000\"")),
            ": PolyData/Piece/PointData/DataArray[Name=MaximumInscribedSphereRadius]: offset 100000 lies beyond "
            "the appended data (" + std::to_string(raw.rfind("</AppendedData>") - raw.find("   _") - 4) + " bytes)");
  // A header that announces more bytes than the array holds.
  const std::string binary = VtpWriter({Mode::binary}).file(y_shape());
  EXPECT_EQ(message("f.vtp", replaced(binary, "NumberOfPoints=\"6\"", "NumberOfPoints=\"5\"")),
            ": PolyData/Piece/Points/DataArray: its header gives 144 bytes, expected 120");
}

TEST_F(ImportVtk, MalformedLegacy) {
  const std::string classic = legacy_classic(y_shape());
  EXPECT_EQ(message("a.vtk", replaced(classic, "ASCII", "BINARY")),
            ":3: binary legacy VTK: hemotree reads legacy files in ASCII (or any .vtp)");
  EXPECT_EQ(message("b.vtk", replaced(classic, "2 3 4", "2 3 x")), ":9: LINES: 'x' is not an integer");
  EXPECT_EQ(message("c.vtk", classic.substr(0, classic.find("LINES") - 5)),
            ":6: the file ends inside POINTS (read 17 of 18 numbers)");
  EXPECT_EQ(message("d.vtk", replaced(classic, "POINT_DATA 6", "POINT_DATA 7")), ":15: POINT_DATA 7: expected 6");
  EXPECT_EQ(message("e.vtk", replaced(classic, "DATASET POLYDATA", "DATASET UNSTRUCTURED_GRID")),
            ":4: hemotree reads DATASET POLYDATA (centerlines)");
}

// Issue 21, defect 9: a count in a few bytes must not allocate for what it announces; each
// is refused by what the file can hold, before any allocation (a refusal after allocating
// would take seconds and gigabytes, or end in bad_alloc, not this InputError).
TEST_F(ImportVtk, LegacyCountsBeyondTheFileAreRefusedAtOnce) {
  const std::string head = "# vtk DataFile Version 3.0\ncenterlines\nASCII\nDATASET POLYDATA\n";
  EXPECT_EQ(message("points.vtk", head + "POINTS 100000000 double\n0 0 0\n"),
            ":5: POINTS: 300000000 numbers cannot fit in the 7 bytes left in the file");
  EXPECT_EQ(message("points_max.vtk", head + "POINTS 1099511627776 double\n0 0 0\n"),
            ":5: POINTS: 3298534883328 numbers cannot fit in the 7 bytes left in the file");
  EXPECT_EQ(message("lines.vtk", head + "POINTS 2 double\n0 0 0 0 0 1\nLINES 1 300000000\n2 0 1\n"),
            ":7: LINES: 300000000 numbers cannot fit in the 7 bytes left in the file");
  // Two counts whose product wraps around 2^64 to 0: saturated, so refused, not read as empty.
  EXPECT_EQ(message("field.vtk", head + "POINTS 2 double\n0 0 0 0 0 1\nFIELD f 1\nr 4294967296 4294967296 double\n"),
            ":8: array r: 18446744073709551615 numbers cannot fit in the 1 bytes left in the file");
}

TEST_F(ImportVtk, XmlCountsBeyondTheDataAreRefusedBeforeAllocating) {
  // 1e8 points of Float64: 2.4e9 bytes announced by a header of a few bytes.
  const auto file = [](const std::string& header_attributes, const std::string& format, const std::string& data) {
    return "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" " +
           header_attributes + ">\n<PolyData><Piece NumberOfPoints=\"100000000\" NumberOfLines=\"1\"><Points>" +
           "<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"" + format + "\">" + data +
           "</DataArray></Points></Piece></PolyData></VTKFile>\n";
  };
  const std::string zlib = "header_type=\"UInt64\" compressor=\"vtkZLibDataCompressor\"";
  const std::string at = ": PolyData/Piece/Points/DataArray: ";
  // 2e8 blocks of 12 bytes: their sizes alone would take 1.6 GB.
  EXPECT_EQ(message("blocks.vtp", file(zlib, "binary", base64(word(200000000, true) + word(12, true) + word(0, true)))),
            at + "its compression header gives 200000000 blocks, but the data hold at most 0 block sizes");
  // One block of 2.4e9 bytes, 16 compressed bytes that are there: more than zlib can inflate.
  EXPECT_EQ(message("ratio.vtp", file(zlib, "binary",
                                      base64(word(1, true) + word(2400000000, true) + word(0, true) + word(16, true)) +
                                          base64(std::string(16, 'x')))),
            at + "its 16 compressed bytes cannot inflate to 2400000000 (zlib inflates at most 1032 times)");
  // One block whose compressed size is more than the file holds.
  EXPECT_EQ(message("oneblock.vtp", file(zlib, "binary",
                                         base64(word(1, true) + word(2400000000, true) + word(0, true) +
                                                word(2000000000, true)))),
            at + "its compressed blocks take more than the 0 bytes the data hold");
  // Uncompressed: the header's size agrees with the count, the bytes are not there.
  EXPECT_EQ(message("raw.vtp", file("header_type=\"UInt64\"", "binary", base64(word(2400000000, true)))),
            at + "its header gives 2400000000 bytes, but the data hold at most 0");
  // ascii: 3e8 numbers announced, 3 given (reserving for the count would take 2.4 GB).
  EXPECT_EQ(message("ascii.vtp", file("", "ascii", "0 0 0")), at + "holds 3 numbers, expected 300000000");
}

// Issue 21, defect 2: 200,000 nested elements overflowed rapidxml's recursion (SIGSEGV).
TEST_F(ImportVtk, DeeplyNestedXmlIsRefusedBeforeParsing) {
  std::string deep = "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"0.1\"><PolyData>";
  for (int k = 0; k < 200000; ++k) deep += "<PolyData>";
  for (int k = 0; k < 200000; ++k) deep += "</PolyData>";
  deep += "</PolyData></VTKFile>\n";
  EXPECT_EQ(message("deep.vtp", deep), ":2: <PolyData> lies 257 elements deep: hemotree reads XML nested at most 256 deep");
}

TEST_F(ImportVtk, RefusesUnmergedBranchTracts) {
  std::string file = VtpWriter({Mode::ascii}).file(y_shape());
  file = replaced(file, "<CellData>\n", "<CellData>\n<DataArray type=\"Int32\" Name=\"GroupIds\" format=\"ascii\">0 1 1</DataArray>\n");
  EXPECT_EQ(message("groups.vtp", file),
            ": polylines 1 and 2 have the same GroupIds 1: vmtkbranchextractor's tracts, one per centerline along "
            "each branch; merge them first (vmtkcenterlinemerge)");
}

TEST_F(ImportVtk, RefusesNonPositiveRadius) {
  Geometry g = y_shape();
  g.radius[3] = 0;
  EXPECT_EQ(message("zero.vtp", VtpWriter({Mode::ascii}).file(g)),
            ": point 3 (3, 0, 9): radius (MaximumInscribedSphereRadius) 0 is not a positive number");
}

TEST_F(ImportVtk, EveryTruncationIsAnInputError) {
  // A file cut anywhere (a partial download) fails with InputError, never otherwise.
  for (Mode mode : {Mode::ascii, Mode::binary, Mode::binary_zlib, Mode::appended_raw, Mode::appended_base64_zlib}) {
    const std::string whole = VtpWriter({mode, true}).file(y_shape());
    const std::string path = write("cut.vtp", "");
    for (std::size_t size = 0; size + 20 < whole.size(); size += 7) {
      std::ofstream(path, std::ios::binary | std::ios::trunc) << whole.substr(0, size);
      EXPECT_THROW(read_vtk_centerline(path, ImportOptions{}), InputError) << "cut at " << size;
    }
  }
}

TEST_F(ImportVtk, UnreadableFileIsIoError) {
  EXPECT_THROW(read_vtk_centerline("/nonexistent/centerlines.vtp", ImportOptions{}), IoError);
}

}  // namespace
}  // namespace hemotree
