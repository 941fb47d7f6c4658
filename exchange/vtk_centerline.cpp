// VTK centerlines: the file is read into points, a radius per point and polylines
// (Centerlines below), whatever the encoding; the network is then built from that geometry
// alone. XML PolyData goes through Boost.PropertyTree once the appended data, raw bytes that
// are not XML, is cut out; each DataArray is decoded from ascii text, base64 (inline or
// appended) or raw appended bytes, each optionally zlib-compressed in VTK's blocks.
#include "exchange/vtk_centerline.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <numeric>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <boost/property_tree/ptree.hpp>
#include <boost/property_tree/xml_parser.hpp>
#include <zlib.h>

#include "core/errors.hpp"
#include "core/setting_error.hpp"
#include "formats/field_ranges.hpp"
#include "formats/topology.hpp"

namespace hemotree {

namespace {

using boost::property_tree::ptree;

// What the file holds, in the file's units: points, one radius per point, polylines as
// point ids (cell c is connectivity[offsets[c] .. offsets[c + 1])).
struct Centerlines {
  std::vector<double> xyz;  // 3 per point
  std::vector<double> radius;
  std::vector<std::int64_t> offsets{0};
  std::vector<std::int64_t> connectivity;
  std::vector<std::string> point_arrays, cell_arrays;  // every array's name, for notes
  std::vector<double> group_ids;                        // cell data GroupIds, if any
  std::size_t vertices = 0;                             // vertex cells, not imported
  std::size_t point_count() const { return radius.size(); }
  std::size_t cell_count() const { return offsets.size() - 1; }
};

std::string join(const std::vector<std::string>& names) {
  if (names.empty()) return "none";
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

bool parse_double(std::string_view text, double& value) {
  const auto r = std::from_chars(text.data(), text.data() + text.size(), value);
  return r.ec == std::errc() && r.ptr == text.data() + text.size();
}

bool is_space(char c) { return c == ' ' || c == '\n' || c == '\r' || c == '\t'; }

// --- binary data ----------------------------------------------------------------------------

// A defect in an array's bytes; the caller adds the file and the element.
struct BadData {
  std::string what;
};

// Bytes of one array, read in order from wherever they lie.
class ByteReader {
 public:
  virtual ~ByteReader() = default;
  // Appends n bytes to out; throws BadData when the data end first.
  virtual void read(std::size_t n, std::string& out) = 0;
  // At most how many bytes are left to read: a header's counts are checked against it
  // before anything is allocated for them.
  virtual std::size_t available() const = 0;
};

class RawReader final : public ByteReader {
 public:
  RawReader(std::string_view data, std::size_t at) : data_(data), at_(at) {}
  void read(std::size_t n, std::string& out) override {
    if (at_ > data_.size() || data_.size() - at_ < n)
      throw BadData{"the appended data end before its " + std::to_string(n) + " bytes"};
    out.append(data_.substr(at_, n));
    at_ += n;
  }
  std::size_t available() const override { return at_ > data_.size() ? 0 : data_.size() - at_; }

 private:
  std::string_view data_;
  std::size_t at_;
};

// Base64, decoded one 4-character quantum at a time. VTK encodes a compressed array's
// header and its blocks as separate base64 texts, each padded, one after the other; a
// quantum that ends in padding simply yields fewer bytes, so both layouts decode alike.
class Base64Reader final : public ByteReader {
 public:
  Base64Reader(std::string_view text, std::size_t at) : text_(text), at_(at) {}
  void read(std::size_t n, std::string& out) override {
    while (n > 0) {
      if (pending_.empty()) next_quantum();
      const std::size_t take = std::min(n, pending_.size());
      out.append(pending_, 0, take);
      pending_.erase(0, take);
      n -= take;
    }
  }
  // Three bytes per four characters left, fewer where there are spaces or padding.
  std::size_t available() const override {
    return pending_.size() + (at_ > text_.size() ? 0 : (text_.size() - at_) / 4 * 3);
  }

 private:
  static int digit(char c) {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+') return 62;
    if (c == '/') return 63;
    return -1;
  }
  void next_quantum() {
    char q[4];
    for (int k = 0; k < 4;) {
      if (at_ >= text_.size()) throw BadData{"the base64 text ends early"};
      const char c = text_[at_++];
      if (is_space(c)) continue;
      if (digit(c) < 0 && c != '=')
        throw BadData{"'" + std::string(1, c) + "' is not a base64 character"};
      q[k++] = c;
    }
    if (q[0] == '=' || q[1] == '=' || (q[2] == '=' && q[3] != '='))
      throw BadData{"misplaced base64 padding '='"};
    const std::uint32_t bits = (std::uint32_t(digit(q[0])) << 18) | (std::uint32_t(digit(q[1])) << 12) |
                               (q[2] == '=' ? 0u : std::uint32_t(digit(q[2])) << 6) |
                               (q[3] == '=' ? 0u : std::uint32_t(digit(q[3])));
    pending_.push_back(static_cast<char>(bits >> 16));
    if (q[2] != '=') pending_.push_back(static_cast<char>((bits >> 8) & 0xff));
    if (q[3] != '=') pending_.push_back(static_cast<char>(bits & 0xff));
  }

  std::string_view text_;
  std::size_t at_;
  std::string pending_;  // decoded bytes not yet read (at most 2)
};

// The encodings the VTKFile element declares for every binary array.
struct Encoding {
  std::size_t header_bytes = 4;  // header_type UInt32 (VTK's default) or UInt64
  bool zlib = false;             // compressor="vtkZLibDataCompressor"
  bool big_endian = false;
};

std::uint64_t to_integer(const std::string& bytes, bool big_endian) {
  std::uint64_t v = 0;
  for (std::size_t k = 0; k < bytes.size(); ++k) {
    const auto byte = static_cast<unsigned char>(bytes[big_endian ? k : bytes.size() - 1 - k]);
    v = (v << 8) | byte;
  }
  return v;
}

// Deflate's densest code, a 258-byte match in about 2 bits: no zlib stream inflates to more
// than 1032 times its own size, so a header that claims more is corrupt, not compressed.
constexpr std::uint64_t zlib_max_ratio = 1032;

// An array's bytes after its header: [size] uncompressed; [blocks, block size, last block
// size (0: a full block), compressed size of each block] then the blocks, zlib-compressed.
// Every size in a header is checked against the bytes present before anything is
// allocated for it: a corrupt header of a few bytes must not allocate gigabytes.
std::string decode_binary(ByteReader& in, const Encoding& enc, std::size_t expected_bytes) {
  auto word = [&] {
    std::string b;
    in.read(enc.header_bytes, b);
    return to_integer(b, enc.big_endian);
  };
  std::string data;
  if (!enc.zlib) {
    const std::uint64_t n = word();
    if (n != expected_bytes)
      throw BadData{"its header gives " + std::to_string(n) + " bytes, expected " + std::to_string(expected_bytes)};
    if (n > in.available())
      throw BadData{"its header gives " + std::to_string(n) + " bytes, but the data hold at most " +
                    std::to_string(in.available())};
    in.read(n, data);
    return data;
  }
  const std::uint64_t blocks = word(), block_size = word(), last_size = word();
  // The blocks' total, (blocks - 1) block_size + last, compared without overflow.
  const bool fits = blocks <= 1 || (blocks - 1 <= expected_bytes && block_size <= expected_bytes / (blocks - 1));
  const std::uint64_t total =
      !fits || blocks == 0 ? 0 : (blocks - 1) * block_size + (last_size ? last_size : block_size);
  if (!fits || total != expected_bytes || (blocks > 0 && last_size > block_size))
    throw BadData{"its compression header gives " + std::to_string(blocks) + " blocks of " +
                  std::to_string(block_size) + " bytes (last " + std::to_string(last_size) + "), expected " +
                  std::to_string(expected_bytes) + " bytes in all"};
  if (blocks > in.available() / enc.header_bytes)
    throw BadData{"its compression header gives " + std::to_string(blocks) + " blocks, but the data hold at most " +
                  std::to_string(in.available() / enc.header_bytes) + " block sizes"};
  std::vector<std::uint64_t> compressed(blocks);
  std::uint64_t compressed_total = 0;
  for (auto& c : compressed) {
    c = word();
    if (c > in.available() || compressed_total + c > in.available())
      throw BadData{"its compressed blocks take more than the " + std::to_string(in.available()) +
                    " bytes the data hold"};
    compressed_total += c;
  }
  if (expected_bytes > zlib_max_ratio * compressed_total)
    throw BadData{"its " + std::to_string(compressed_total) + " compressed bytes cannot inflate to " +
                  std::to_string(expected_bytes) + " (zlib inflates at most " + std::to_string(zlib_max_ratio) +
                  " times)"};
  data.resize(expected_bytes);
  std::size_t at = 0;
  std::string block;
  for (std::uint64_t b = 0; b < blocks; ++b) {
    const std::uint64_t size = (b + 1 == blocks && last_size) ? last_size : block_size;
    block.clear();
    in.read(compressed[b], block);
    uLongf inflated = static_cast<uLongf>(size);
    const int rc = uncompress(reinterpret_cast<Bytef*>(data.data() + at), &inflated,
                              reinterpret_cast<const Bytef*>(block.data()), static_cast<uLong>(block.size()));
    if (rc != Z_OK || inflated != size)
      throw BadData{"zlib block " + std::to_string(b) + " does not inflate to " + std::to_string(size) +
                    " bytes (" + (rc == Z_OK ? "size differs" : zError(rc)) + ")"};
    at += size;
  }
  return data;
}

std::size_t type_size(std::string_view type) {
  if (type == "Int8" || type == "UInt8") return 1;
  if (type == "Int16" || type == "UInt16") return 2;
  if (type == "Int32" || type == "UInt32" || type == "Float32") return 4;
  if (type == "Int64" || type == "UInt64" || type == "Float64") return 8;
  return 0;
}

template <class T>
double value_of(const char* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return static_cast<double>(v);
}

std::vector<double> to_values(std::string& bytes, std::string_view type, bool big_endian) {
  const std::size_t size = type_size(type);
  std::vector<double> values(bytes.size() / size);
  for (std::size_t i = 0; i < values.size(); ++i) {
    char* p = bytes.data() + i * size;
    if (big_endian) std::reverse(p, p + size);  // hemotree runs on little-endian machines
    if (type == "Float64") values[i] = value_of<double>(p);
    else if (type == "Float32") values[i] = value_of<float>(p);
    else if (type == "Int8") values[i] = value_of<std::int8_t>(p);
    else if (type == "UInt8") values[i] = value_of<std::uint8_t>(p);
    else if (type == "Int16") values[i] = value_of<std::int16_t>(p);
    else if (type == "UInt16") values[i] = value_of<std::uint16_t>(p);
    else if (type == "Int32") values[i] = value_of<std::int32_t>(p);
    else if (type == "UInt32") values[i] = value_of<std::uint32_t>(p);
    else if (type == "Int64") values[i] = value_of<std::int64_t>(p);
    else values[i] = value_of<std::uint64_t>(p);
  }
  return values;
}

// --- XML PolyData ---------------------------------------------------------------------------

struct XmlFile {
  std::string path;
  Encoding encoding;
  std::string appended;  // the bytes after AppendedData's '_'
  bool appended_raw = false;
  [[noreturn]] void fail(const std::string& element, const std::string& what) const {
    throw_input_error(path + ": " + element + ": " + what);
  }
};

std::string attribute(const ptree& element, const std::string& name, const std::string& otherwise = "") {
  return element.get<std::string>("<xmlattr>." + name, otherwise);
}

std::size_t count_attribute(const XmlFile& f, const ptree& element, const std::string& where,
                            const std::string& name) {
  const std::string text = attribute(element, name, "0");
  std::uint64_t n = 0;
  const auto r = std::from_chars(text.data(), text.data() + text.size(), n);
  if (r.ec != std::errc() || r.ptr != text.data() + text.size() || n > (std::uint64_t(1) << 40))
    f.fail(where, name + "=\"" + text + "\" is not a count");
  return static_cast<std::size_t>(n);
}

// Reads a DataArray of `tuples` tuples of `components` numbers, in any encoding.
std::vector<double> read_data_array(const XmlFile& f, const ptree& array, const std::string& where,
                                    std::size_t tuples, std::size_t components) {
  const std::string type = attribute(array, "type");
  if (type_size(type) == 0)
    f.fail(where, "type=\"" + type + "\": hemotree reads Int8 .. Int64, UInt8 .. UInt64, Float32, Float64");
  const std::string comp_text = attribute(array, "NumberOfComponents", "1");
  if (comp_text != std::to_string(components))
    f.fail(where, "NumberOfComponents=\"" + comp_text + "\", expected " + std::to_string(components));
  const std::size_t count = tuples * components;
  const std::string format = attribute(array, "format");
  try {
    if (format == "ascii") {
      std::vector<double> values;
      const std::string& text = array.data();
      values.reserve(std::min(count, text.size() / 2 + 1));  // a number and a space each, at least
      for (std::size_t at = 0; at < text.size();) {
        while (at < text.size() && is_space(text[at])) ++at;
        std::size_t end = at;
        while (end < text.size() && !is_space(text[end])) ++end;
        if (end == at) break;
        double v;
        if (!parse_double(std::string_view(text).substr(at, end - at), v))
          throw BadData{"'" + text.substr(at, end - at) + "' is not a number"};
        values.push_back(v);
        at = end;
      }
      if (values.size() != count)
        throw BadData{"holds " + std::to_string(values.size()) + " numbers, expected " + std::to_string(count)};
      return values;
    }
    std::string bytes;
    const std::size_t expected = count * type_size(type);
    if (format == "binary") {
      Base64Reader in(array.data(), 0);
      bytes = decode_binary(in, f.encoding, expected);
    } else if (format == "appended") {
      const std::string offset_text = attribute(array, "offset");
      std::uint64_t offset = 0;
      const auto r = std::from_chars(offset_text.data(), offset_text.data() + offset_text.size(), offset);
      if (r.ec != std::errc() || r.ptr != offset_text.data() + offset_text.size())
        throw BadData{"offset=\"" + offset_text + "\" is not a byte offset"};
      if (offset > f.appended.size())
        throw BadData{"offset " + offset_text + " lies beyond the appended data (" +
                      std::to_string(f.appended.size()) + " bytes)"};
      if (f.appended_raw) {
        RawReader in(f.appended, offset);
        bytes = decode_binary(in, f.encoding, expected);
      } else {
        Base64Reader in(f.appended, offset);
        bytes = decode_binary(in, f.encoding, expected);
      }
    } else {
      throw BadData{"format=\"" + format + "\": VTK's are ascii, binary and appended"};
    }
    return to_values(bytes, type, f.encoding.big_endian);
  } catch (const BadData& e) {
    f.fail(where, e.what);
  }
}

const ptree* named_array(const ptree& parent, const std::string& name) {
  for (const auto& [tag, child] : parent)
    if (tag == "DataArray" && attribute(child, "Name") == name) return &child;
  return nullptr;
}

std::vector<std::string> array_names(const ptree* parent) {
  std::vector<std::string> names;
  if (parent)
    for (const auto& [tag, child] : *parent)
      if (tag == "DataArray") names.push_back(attribute(child, "Name"));
  return names;
}

// Cuts out the AppendedData section's content (from its '_' to its closing tag): raw bytes
// are not XML, and base64 there is read by offset anyway.
std::string cut_appended(XmlFile& f, std::string text) {
  const std::size_t at = text.find("<AppendedData");
  if (at == std::string::npos) return text;
  const std::string where = "VTKFile/AppendedData";
  const std::size_t tag_end = text.find('>', at);
  if (tag_end == std::string::npos) f.fail(where, "the tag is not closed");
  const std::string tag = text.substr(at, tag_end - at);
  if (tag.find("encoding=\"raw\"") != std::string::npos) f.appended_raw = true;
  else if (tag.find("encoding=\"base64\"") == std::string::npos)
    f.fail(where, "encoding must be \"raw\" or \"base64\"");
  const std::size_t close = text.rfind("</AppendedData>");
  if (close == std::string::npos || close < tag_end) f.fail(where, "no closing </AppendedData>");
  std::size_t mark = tag_end + 1;
  while (mark < close && is_space(text[mark])) ++mark;
  if (mark >= close || text[mark] != '_') f.fail(where, "the data do not begin with '_'");
  f.appended = text.substr(mark + 1, close - mark - 1);
  return text.substr(0, tag_end + 1) + text.substr(close);
}

Centerlines read_xml(const std::string& path, std::string text, const CenterlineOptions& options) {
  XmlFile f;
  f.path = path;
  const std::string xml = cut_appended(f, std::move(text));
  refuse_deep_xml(path, xml);  // before the recursive parser: deep nesting would overflow its stack
  ptree tree;
  try {
    std::istringstream in(xml);
    boost::property_tree::read_xml(in, tree, boost::property_tree::xml_parser::no_comments);
  } catch (const boost::property_tree::xml_parser_error& e) {
    throw InputError(path + ":" + std::to_string(e.line()) + ": not well-formed XML: " + e.message());
  }
  const auto vtk = tree.get_child_optional("VTKFile");
  if (!vtk) f.fail("VTKFile", "missing: the root element must be <VTKFile>");
  if (attribute(*vtk, "type") != "PolyData")
    f.fail("VTKFile", "type=\"" + attribute(*vtk, "type") +
                          "\": centerlines are PolyData (.vtp); hemotree reads no other VTK data set");
  const std::string header = attribute(*vtk, "header_type", "UInt32");
  if (header == "UInt64") f.encoding.header_bytes = 8;
  else if (header != "UInt32") f.fail("VTKFile", "header_type=\"" + header + "\": must be UInt32 or UInt64");
  const std::string compressor = attribute(*vtk, "compressor");
  if (compressor == "vtkZLibDataCompressor") f.encoding.zlib = true;
  else if (!compressor.empty())
    f.fail("VTKFile", "compressor=\"" + compressor +
                          "\": hemotree reads zlib-compressed (vtkZLibDataCompressor) or uncompressed data");
  const std::string order = attribute(*vtk, "byte_order", "LittleEndian");
  if (order == "BigEndian") f.encoding.big_endian = true;
  else if (order != "LittleEndian") f.fail("VTKFile", "byte_order=\"" + order + "\"");

  const auto poly = vtk->get_child_optional("PolyData");
  if (!poly) f.fail("VTKFile", "no <PolyData> element");
  if (poly->count("Piece") != 1)
    f.fail("PolyData", std::to_string(poly->count("Piece")) + " pieces: hemotree reads a file of one piece");
  const ptree& piece = poly->get_child("Piece");
  const std::string at = "PolyData/Piece";
  const std::size_t points = count_attribute(f, piece, at, "NumberOfPoints");
  const std::size_t lines = count_attribute(f, piece, at, "NumberOfLines");
  for (const char* surface : {"NumberOfPolys", "NumberOfStrips"})
    if (count_attribute(f, piece, at, surface) > 0)
      f.fail(at, std::string(surface) + "=\"" + attribute(piece, surface) +
                     "\": a surface, not centerlines (vmtkcenterlines computes them from a surface)");
  if (lines == 0) f.fail(at, "NumberOfLines=\"0\": no polylines");

  Centerlines c;
  c.vertices = count_attribute(f, piece, at, "NumberOfVerts");
  const auto points_element = piece.get_child_optional("Points");
  const auto points_array = points_element ? points_element->get_child_optional("DataArray") : boost::none;
  if (!points_array) f.fail(at + "/Points", "missing, or without a DataArray");
  c.xyz = read_data_array(f, *points_array, at + "/Points/DataArray", points, 3);

  const auto lines_element = piece.get_child_optional("Lines");
  if (!lines_element) f.fail(at, "no <Lines> element");
  const ptree* offsets = named_array(*lines_element, "offsets");
  const ptree* connectivity = named_array(*lines_element, "connectivity");
  if (!offsets) f.fail(at + "/Lines", "no DataArray Name=\"offsets\"");
  if (!connectivity) f.fail(at + "/Lines", "no DataArray Name=\"connectivity\"");
  const std::string offsets_at = at + "/Lines/DataArray[Name=offsets]";
  const std::vector<double> ends = read_data_array(f, *offsets, offsets_at, lines, 1);
  for (std::size_t k = 0; k < ends.size(); ++k) {
    if (ends[k] < double(c.offsets.back()) || ends[k] != std::floor(ends[k]) || ends[k] > 1e15)
      f.fail(offsets_at, "value " + std::to_string(k) + " (" + format_number(ends[k]) +
                             ") is not an offset at or after the previous one");
    c.offsets.push_back(static_cast<std::int64_t>(ends[k]));
  }
  const std::string connectivity_at = at + "/Lines/DataArray[Name=connectivity]";
  for (double id : read_data_array(f, *connectivity, connectivity_at, static_cast<std::size_t>(c.offsets.back()), 1)) {
    if (!(id >= 0 && id < double(points)) || id != std::floor(id))
      f.fail(connectivity_at, "point id " + format_number(id) + " outside [0, " + std::to_string(points) + ")");
    c.connectivity.push_back(static_cast<std::int64_t>(id));
  }

  const auto point_data = piece.get_child_optional("PointData");
  const auto cell_data = piece.get_child_optional("CellData");
  c.point_arrays = array_names(point_data.get_ptr());
  c.cell_arrays = array_names(cell_data.get_ptr());
  const ptree* radius = point_data ? named_array(*point_data, options.radius_array) : nullptr;
  if (!radius)
    f.fail(at + "/PointData", "no DataArray Name=\"" + options.radius_array + "\" (point data arrays: " +
                                  join(c.point_arrays) + "; cell data arrays: " + join(c.cell_arrays) +
                                  "); vimport " + placeholder("radius_array") + " names another");
  c.radius = read_data_array(f, *radius, at + "/PointData/DataArray[Name=" + options.radius_array + "]", points, 1);
  if (const ptree* groups = cell_data ? named_array(*cell_data, "GroupIds") : nullptr)
    c.group_ids = read_data_array(f, *groups, at + "/CellData/DataArray[Name=GroupIds]", lines, 1);
  return c;
}

// --- legacy ASCII .vtk ----------------------------------------------------------------------

class LegacyReader {
 public:
  LegacyReader(std::string path, std::string text) : path_(std::move(path)), text_(std::move(text)) {}

  Centerlines read(const CenterlineOptions& options) {
    if (line_text().rfind("# vtk DataFile", 0) != 0) fail("not a legacy VTK file (no '# vtk DataFile' line)");
    skip_line();
    skip_line();  // the title
    const std::string mode = word("ASCII or BINARY");
    if (mode == "BINARY") fail("binary legacy VTK: hemotree reads legacy files in ASCII (or any .vtp)");
    if (mode != "ASCII") fail("expected ASCII, got '" + mode + "'");
    if (word("DATASET") != "DATASET" || word("POLYDATA") != "POLYDATA")
      fail("hemotree reads DATASET POLYDATA (centerlines)");
    Centerlines c;
    bool have_points = false, have_radius = false;
    std::size_t lines_cells = 0, section_count = 0;
    std::string section;  // POINT_DATA or CELL_DATA
    while (!at_end()) {
      const std::string key = word("a keyword");
      if (key == "POINTS") {
        const std::size_t n = count("the point count");
        word("the data type");
        c.xyz = numbers(3 * n, "POINTS");
        c.radius.assign(n, std::nan(""));
        have_points = true;
      } else if (key == "LINES" || key == "VERTS" || key == "POLYGONS" || key == "TRIANGLE_STRIPS") {
        const std::size_t cells = count("the cell count"), size = count("the size");
        if ((key == "POLYGONS" || key == "TRIANGLE_STRIPS") && cells > 0)
          fail(key + ": a surface, not centerlines (vmtkcenterlines computes them from a surface)");
        std::vector<std::int64_t> offsets, ids;
        read_cells(key, cells, size, offsets, ids);
        if (key == "LINES") {
          c.offsets = std::move(offsets);
          c.connectivity = std::move(ids);
          lines_cells = c.cell_count();
        } else {
          c.vertices += offsets.size() - 1;
        }
      } else if (key == "POINT_DATA" || key == "CELL_DATA") {
        section = key;
        section_count = count("the tuple count");
        const std::size_t expected = key == "POINT_DATA" ? c.point_count() : lines_cells + c.vertices;
        if (section_count != expected)
          fail(key + " " + std::to_string(section_count) + ": expected " + std::to_string(expected));
      } else if (key == "SCALARS") {
        const std::string name = word("the array name"), type = word("the data type");
        std::size_t components = 1;
        if (!next_is_keyword()) components = count("the component count");
        if (peek_word() == "LOOKUP_TABLE") {
          word("");
          word("the lookup table name");
        }
        auto values = numbers(product(components, section_count), "SCALARS " + name);
        keep(c, section, name, components, std::move(values), options, have_radius);
      } else if (key == "FIELD") {
        word("the field name");
        const std::size_t arrays = count("the array count");
        for (std::size_t a = 0; a < arrays; ++a) {
          if (peek_word() == "METADATA") skip_metadata();
          const std::string name = word("the array name");
          const std::size_t components = count("the component count"), tuples = count("the tuple count");
          word("the data type");
          auto values = numbers(product(components, tuples), "array " + name);
          if (!section.empty() && tuples != section_count)
            fail("array " + name + " has " + std::to_string(tuples) + " tuples, " + section + " has " +
                 std::to_string(section_count));
          if (!section.empty()) keep(c, section, name, components, std::move(values), options, have_radius);
        }
      } else if (key == "VECTORS" || key == "NORMALS" || key == "TENSORS" || key == "GLOBAL_IDS" ||
                 key == "PEDIGREE_IDS") {
        const std::string name = word("the array name");
        word("the data type");
        const std::size_t per = key == "TENSORS" ? 9 : (key == "VECTORS" || key == "NORMALS") ? 3 : 1;
        numbers(per * section_count, key + " " + name);
        (section == "POINT_DATA" ? c.point_arrays : c.cell_arrays).push_back(name);
      } else if (key == "TEXTURE_COORDINATES") {
        const std::string name = word("the array name");
        const std::size_t dim = count("the dimension");
        word("the data type");
        numbers(product(dim, section_count), key + " " + name);
        (section == "POINT_DATA" ? c.point_arrays : c.cell_arrays).push_back(name);
      } else if (key == "COLOR_SCALARS") {
        const std::string name = word("the array name");
        numbers(product(count("the component count"), section_count), key + " " + name);
        (section == "POINT_DATA" ? c.point_arrays : c.cell_arrays).push_back(name);
      } else if (key == "LOOKUP_TABLE") {
        word("the table name");
        numbers(4 * count("the table size"), "LOOKUP_TABLE");
      } else if (key == "METADATA") {
        skip_metadata();
      } else {
        fail("unknown keyword '" + key + "'");
      }
    }
    if (!have_points) fail_file("no POINTS");
    if (lines_cells == 0) fail_file("no LINES: no polylines");
    for (std::int64_t id : c.connectivity)
      if (id < 0 || static_cast<std::size_t>(id) >= c.point_count())
        fail_file("LINES: point id " + std::to_string(id) + " outside [0, " + std::to_string(c.point_count()) + ")");
    if (!have_radius)
      fail_file("no point data array \"" + options.radius_array + "\" (point data arrays: " + join(c.point_arrays) +
           "; cell data arrays: " + join(c.cell_arrays) + "); vimport " + placeholder("radius_array") + " names another");
    return c;
  }

 private:
  void keep(Centerlines& c, const std::string& section, const std::string& name, std::size_t components,
            std::vector<double> values, const CenterlineOptions& options, bool& have_radius) {
    if (section == "POINT_DATA") {
      c.point_arrays.push_back(name);
      if (name == options.radius_array) {
        if (components != 1) fail("array " + name + " has " + std::to_string(components) + " components, expected 1");
        c.radius = std::move(values);
        have_radius = true;
      }
    } else if (section == "CELL_DATA") {
      c.cell_arrays.push_back(name);
      // The vertex cells come first in legacy cell data, then the lines.
      if (name == "GroupIds" && components == 1) c.group_ids.assign(values.begin() + static_cast<long>(c.vertices), values.end());
    } else {
      fail("array " + name + " outside POINT_DATA or CELL_DATA");
    }
  }

  // Classic layout: per cell, its point count then its ids (size numbers in all); VTK 5.1:
  // OFFSETS (cells numbers, the first 0) and CONNECTIVITY (size numbers).
  void read_cells(const std::string& key, std::size_t cells, std::size_t size, std::vector<std::int64_t>& offsets,
                  std::vector<std::int64_t>& ids) {
    fits(size, key);  // either layout holds size numbers at least; said at the count's line
    offsets.assign(1, 0);
    if (peek_word() == "OFFSETS") {
      word("");
      word("the data type");
      const auto o = integers(cells, key + " OFFSETS");
      if (word("CONNECTIVITY") != "CONNECTIVITY") fail(key + ": expected CONNECTIVITY after OFFSETS");
      word("the data type");
      ids = integers(size, key + " CONNECTIVITY");
      if (cells == 0) return;
      if (o.front() != 0 || static_cast<std::size_t>(o.back()) != size || !std::is_sorted(o.begin(), o.end()))
        fail(key + ": OFFSETS must rise from 0 to the connectivity's size");
      offsets.assign(o.begin(), o.end());
      return;
    }
    const auto all = integers(size, key);
    for (std::size_t at = 0, cell = 0; cell < cells; ++cell) {
      if (at >= all.size() || all[at] < 0 || static_cast<std::size_t>(all[at]) > all.size() - at - 1)
        fail(key + ": cell " + std::to_string(cell) + " runs past the " + std::to_string(size) + " numbers");
      const auto n = static_cast<std::size_t>(all[at]);
      ids.insert(ids.end(), all.begin() + static_cast<long>(at + 1), all.begin() + static_cast<long>(at + 1 + n));
      offsets.push_back(static_cast<std::int64_t>(ids.size()));
      at += n + 1;
      if (cell + 1 == cells && at != size) fail(key + ": the cells hold fewer than " + std::to_string(size) + " numbers");
    }
  }

  [[noreturn]] void fail(const std::string& what) const {
    throw_input_error(path_ + ":" + std::to_string(line_) + ": " + what);
  }
  [[noreturn]] void fail_file(const std::string& what) const { throw_input_error(path_ + ": " + what); }
  void skip_blank() {
    while (pos_ < text_.size() && is_space(text_[pos_])) {
      if (text_[pos_] == '\n') ++line_;
      ++pos_;
    }
  }
  bool at_end() {
    skip_blank();
    return pos_ >= text_.size();
  }
  std::string line_text() const {
    const std::size_t end = text_.find('\n', pos_);
    return text_.substr(pos_, end == std::string::npos ? std::string::npos : end - pos_);
  }
  void skip_line() {
    const std::size_t end = text_.find('\n', pos_);
    pos_ = end == std::string::npos ? text_.size() : end + 1;
    ++line_;
  }
  std::string_view peek_word() {
    skip_blank();
    std::size_t end = pos_;
    while (end < text_.size() && !is_space(text_[end])) ++end;
    return std::string_view(text_).substr(pos_, end - pos_);
  }
  bool next_is_keyword() {
    const std::string_view w = peek_word();
    return w.empty() || std::isalpha(static_cast<unsigned char>(w[0]));
  }
  std::string word(const std::string& what) {
    const std::string w(peek_word());
    if (w.empty()) fail("the file ends where " + what + " should be");
    pos_ += w.size();
    return w;
  }
  std::size_t count(const std::string& what) {
    const std::string w = word(what);
    std::uint64_t n = 0;
    const auto r = std::from_chars(w.data(), w.data() + w.size(), n);
    if (r.ec != std::errc() || r.ptr != w.data() + w.size() || n > (std::uint64_t(1) << 40))
      fail("expected " + what + ", got '" + w + "'");
    return static_cast<std::size_t>(n);
  }
  // Two counts multiplied, at most 2^80: saturated rather than wrapped, for fits() to refuse.
  static std::size_t product(std::size_t a, std::size_t b) {
    return b != 0 && a > std::numeric_limits<std::size_t>::max() / b ? std::numeric_limits<std::size_t>::max() : a * b;
  }
  // Refuses at once a count of numbers that the rest of the file cannot hold (each takes a
  // character and a space at least), before anything is allocated for them: "POINTS
  // 100000000" in an 82-byte file must not allocate gigabytes.
  void fits(std::size_t n, const std::string& what) const {
    const std::size_t left = text_.size() - pos_;
    if (n > left / 2 + 1)
      fail(what + ": " + std::to_string(n) + " numbers cannot fit in the " + std::to_string(left) +
           " bytes left in the file");
  }
  std::vector<double> numbers(std::size_t n, const std::string& what) {
    fits(n, what);
    std::vector<double> values(n);
    for (std::size_t k = 0; k < n; ++k) {
      const std::string_view w = peek_word();
      if (w.empty()) fail("the file ends inside " + what + " (read " + std::to_string(k) + " of " + std::to_string(n) + " numbers)");
      if (!parse_double(w, values[k])) fail(what + ": '" + std::string(w) + "' is not a number");
      pos_ += w.size();
    }
    return values;
  }
  std::vector<std::int64_t> integers(std::size_t n, const std::string& what) {
    fits(n, what);
    std::vector<std::int64_t> values(n);
    for (std::size_t k = 0; k < n; ++k) {
      const std::string_view w = peek_word();
      if (w.empty()) fail("the file ends inside " + what + " (read " + std::to_string(k) + " of " + std::to_string(n) + " numbers)");
      const auto r = std::from_chars(w.data(), w.data() + w.size(), values[k]);
      if (r.ec != std::errc() || r.ptr != w.data() + w.size()) fail(what + ": '" + std::string(w) + "' is not an integer");
      pos_ += w.size();
    }
    return values;
  }
  // VTK 5.1 writes METADATA blocks that end at an empty line.
  void skip_metadata() {
    skip_line();
    while (pos_ < text_.size()) {
      const std::string l = line_text();
      skip_line();
      if (std::all_of(l.begin(), l.end(), is_space)) return;
    }
  }

  std::string path_, text_;
  std::size_t pos_ = 0, line_ = 1;
};

// --- the network ----------------------------------------------------------------------------

struct UnionFind {
  std::vector<std::size_t> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  std::size_t find(std::size_t a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  }
  void join(std::size_t a, std::size_t b) {  // the smaller index represents the set
    a = find(a);
    b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
};

double distance(const std::vector<double>& xyz, std::size_t a, std::size_t b) {
  return std::hypot(xyz[3 * a] - xyz[3 * b], xyz[3 * a + 1] - xyz[3 * b + 1], xyz[3 * a + 2] - xyz[3 * b + 2]);
}

// Points of different polylines at the same place are one point: VMTK's tools join
// centerlines by repeating the junction's coordinates rather than sharing its id.
// Coincident means within 1e-9 of the model's size (its bounding box diagonal).
std::size_t merge_coincident(const Centerlines& c, UnionFind& same) {
  const std::size_t n = c.point_count();
  double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
  for (std::size_t p = 0; p < n; ++p)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], c.xyz[3 * p + k]);
      hi[k] = std::max(hi[k], c.xyz[3 * p + k]);
    }
  const double tolerance = 1e-9 * std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
  std::vector<std::size_t> by_x(n);
  std::iota(by_x.begin(), by_x.end(), 0);
  std::sort(by_x.begin(), by_x.end(), [&](std::size_t a, std::size_t b) { return c.xyz[3 * a] < c.xyz[3 * b]; });
  std::size_t merged = 0;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n && c.xyz[3 * by_x[j]] - c.xyz[3 * by_x[i]] <= tolerance; ++j)
      if (distance(c.xyz, by_x[i], by_x[j]) <= tolerance && same.find(by_x[i]) != same.find(by_x[j])) {
        same.join(by_x[i], by_x[j]);
        ++merged;
      }
  return merged;
}

struct Segment {
  std::size_t a, b;  // merged points, in the polyline's order
  std::size_t cell;
};

// A chain of points between two nodes (junctions or ends), as one vessel.
struct Chain {
  std::vector<std::size_t> points;
  std::size_t cell;  // the polyline it was found in, for messages
};

std::string point_text(const Centerlines& c, std::size_t p) {
  return "point " + std::to_string(p) + " (" + format_number(c.xyz[3 * p]) + ", " + format_number(c.xyz[3 * p + 1]) +
         ", " + format_number(c.xyz[3 * p + 2]) + ")";
}

std::string plural(std::size_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

Network build_network(const std::string& path, const Centerlines& c, const ImportOptions& options,
                      const CenterlineOptions& co) {
  for (std::size_t p = 0; p < c.point_count(); ++p) {
    if (!std::isfinite(c.xyz[3 * p]) || !std::isfinite(c.xyz[3 * p + 1]) || !std::isfinite(c.xyz[3 * p + 2]))
      throw InputError(path + ": point " + std::to_string(p) + " has a coordinate that is not a finite number");
    if (!(c.radius[p] > 0) || !std::isfinite(c.radius[p]))
      throw InputError(path + ": " + point_text(c, p) + ": radius (" + co.radius_array + ") " +
                       format_number(c.radius[p]) + " is not a positive number");
  }
  if (!c.group_ids.empty()) {
    std::vector<std::pair<double, std::size_t>> groups;
    for (std::size_t k = 0; k < c.group_ids.size(); ++k) groups.push_back({c.group_ids[k], k});
    std::sort(groups.begin(), groups.end());
    for (std::size_t k = 1; k < groups.size(); ++k)
      if (groups[k].first == groups[k - 1].first)
        throw InputError(path + ": polylines " + std::to_string(groups[k - 1].second) + " and " +
                         std::to_string(groups[k].second) + " have the same GroupIds " +
                         format_number(groups[k].first) +
                         ": vmtkbranchextractor's tracts, one per centerline along each branch; merge them "
                         "first (vmtkcenterlinemerge)");
  }

  UnionFind same(c.point_count());
  const std::size_t coincident = merge_coincident(c, same);

  // Segments, each once: overlapping polylines through the same points give it twice.
  std::vector<Segment> segments;
  std::size_t repeated_points = 0, single_point_cells = 0;
  for (std::size_t cell = 0; cell < c.cell_count(); ++cell) {
    const auto begin = static_cast<std::size_t>(c.offsets[cell]), end = static_cast<std::size_t>(c.offsets[cell + 1]);
    if (end - begin < 2) ++single_point_cells;
    for (std::size_t k = begin; k + 1 < end; ++k) {
      const std::size_t a = same.find(static_cast<std::size_t>(c.connectivity[k]));
      const std::size_t b = same.find(static_cast<std::size_t>(c.connectivity[k + 1]));
      if (a == b) ++repeated_points;
      else segments.push_back({a, b, cell});
    }
  }
  std::vector<std::size_t> order(segments.size());
  std::iota(order.begin(), order.end(), 0);
  const auto key = [&](std::size_t s) { return std::minmax(segments[s].a, segments[s].b); };
  std::stable_sort(order.begin(), order.end(), [&](std::size_t s, std::size_t t) { return key(s) < key(t); });
  std::vector<char> duplicate(segments.size(), 0);
  for (std::size_t k = 1; k < order.size(); ++k)
    if (key(order[k]) == key(order[k - 1])) duplicate[order[k]] = 1;
  std::vector<Segment> unique;
  for (std::size_t s = 0; s < segments.size(); ++s)
    if (!duplicate[s]) unique.push_back(segments[s]);
  const std::size_t overlapping = segments.size() - unique.size();
  if (unique.empty()) throw InputError(path + ": the polylines have no segment of two distinct points");

  // Segments at each point (CSR); nodes are the points where one or three and more meet.
  const std::size_t n = c.point_count();
  std::vector<std::size_t> first(n + 1, 0), at(2 * unique.size());
  for (const Segment& s : unique) ++first[s.a + 1], ++first[s.b + 1];
  for (std::size_t p = 0; p < n; ++p) first[p + 1] += first[p];
  std::vector<std::size_t> fill(first.begin(), first.end() - 1);
  for (std::size_t s = 0; s < unique.size(); ++s) at[fill[unique[s].a]++] = at[fill[unique[s].b]++] = s;
  const auto degree = [&](std::size_t p) { return first[p + 1] - first[p]; };

  // vmtkcenterlines writes one centerline from the inlet to each outlet: they run side by
  // side along common trunks without sharing points. Such pieces leave a point together: at
  // two radii from it they are still within 5% of a radius of each other, where the
  // daughters of any real bifurcation (20 degrees apart or more) are 0.7 radii apart.
  // Checked wherever pieces meet: at junctions and where polylines end on one another.
  std::vector<char> polyline_end(n, 0);
  for (std::size_t cell = 0; cell < c.cell_count(); ++cell)
    if (c.offsets[cell + 1] > c.offsets[cell]) {
      polyline_end[same.find(static_cast<std::size_t>(c.connectivity[static_cast<std::size_t>(c.offsets[cell])]))] = 1;
      polyline_end[same.find(static_cast<std::size_t>(c.connectivity[static_cast<std::size_t>(c.offsets[cell + 1] - 1)]))] = 1;
    }
  auto ahead_of = [&](std::size_t p, std::size_t s, double left) -> std::array<double, 3> {
    for (;;) {
      const std::size_t q = unique[s].a == p ? unique[s].b : unique[s].a;
      const double l = distance(c.xyz, p, q);
      if (l >= left || degree(q) != 2) {
        const double t = std::min(1.0, left / l);
        return {c.xyz[3 * p] + t * (c.xyz[3 * q] - c.xyz[3 * p]), c.xyz[3 * p + 1] + t * (c.xyz[3 * q + 1] - c.xyz[3 * p + 1]),
                c.xyz[3 * p + 2] + t * (c.xyz[3 * q + 2] - c.xyz[3 * p + 2])};
      }
      left -= l;
      s = at[first[q]] == s ? at[first[q] + 1] : at[first[q]];
      p = q;
    }
  };
  for (std::size_t p = 0; p < n; ++p) {
    if (degree(p) < 2 || (degree(p) == 2 && !polyline_end[p])) continue;
    const double r = c.radius[p];
    std::vector<std::array<double, 3>> ahead;
    for (std::size_t k = first[p]; k < first[p + 1]; ++k) ahead.push_back(ahead_of(p, at[k], 2 * r));
    for (std::size_t i = 0; i < ahead.size(); ++i)
      for (std::size_t j = i + 1; j < ahead.size(); ++j)
        if (std::hypot(ahead[i][0] - ahead[j][0], ahead[i][1] - ahead[j][1], ahead[i][2] - ahead[j][2]) < 0.05 * r)
          throw InputError(path + ": polylines " + std::to_string(unique[at[first[p] + i]].cell) + " and " +
                           std::to_string(unique[at[first[p] + j]].cell) + " leave " + point_text(c, p) +
                           " side by side (within 0.05 radii over 2 radii): overlapping centerlines, as "
                           "vmtkcenterlines writes one from the inlet to each outlet; split and merge them "
                           "first (vmtkbranchextractor, then vmtkcenterlinemerge)");
  }

  // Chains, found in the polylines' order and oriented as written there.
  std::vector<char> used(unique.size(), 0);
  std::vector<Chain> chains;
  auto walk = [&](std::size_t p, std::size_t from_segment, std::vector<std::size_t>& out) {
    while (degree(p) == 2) {
      const std::size_t s = at[first[p]] == from_segment ? at[first[p] + 1] : at[first[p]];
      if (used[s])
        throw InputError(path + ": polyline " + std::to_string(unique[s].cell) +
                         " closes a loop with no junction on it: a vessel needs two distinct ends");
      used[s] = 1;
      p = unique[s].a == p ? unique[s].b : unique[s].a;
      out.push_back(p);
      from_segment = s;
    }
  };
  for (std::size_t s = 0; s < unique.size(); ++s) {
    if (used[s]) continue;
    used[s] = 1;
    std::vector<std::size_t> back{unique[s].a}, ahead{unique[s].b};
    walk(unique[s].a, s, back);
    walk(unique[s].b, s, ahead);
    Chain chain{{back.rbegin(), back.rend()}, unique[s].cell};
    chain.points.insert(chain.points.end(), ahead.begin(), ahead.end());
    if (chain.points.front() == chain.points.back())
      throw InputError(path + ": polyline " + std::to_string(chain.cell) + " leaves " +
                       point_text(c, chain.points.front()) +
                       " and comes back to it: a vessel needs two distinct ends");
    chains.push_back(std::move(chain));
  }

  // Nodes in the order the chains meet them; the id is the point's (the smallest merged).
  const double u = co.length_unit;
  Network net;
  std::vector<std::int32_t> node_of(n, -1);
  auto node = [&](std::size_t p) {
    if (node_of[p] < 0)
      node_of[p] = net.add_node(static_cast<std::int64_t>(p), u * c.xyz[3 * p], u * c.xyz[3 * p + 1], u * c.xyz[3 * p + 2]);
    return node_of[p];
  };
  for (const Chain& chain : chains) {
    node(chain.points.front());
    node(chain.points.back());
  }

  const std::string unit_hint = "; the file's lengths were read as " + format_number(u) +
                                " m each (vimport " + placeholder("unit") + " sets the unit, e.g. " + placeholder("unit") + " mm)";
  static const char* const axis_name[3] = {"x", "y", "z"};
  for (std::size_t k = 0; k < chains.size(); ++k) {
    const auto& p = chains[k].points;
    double length = 0, radius_integral = 0;  // trapezoidal: the radius varies linearly along a segment
    for (std::size_t i = 0; i + 1 < p.size(); ++i) {
      const double l = distance(c.xyz, p[i], p[i + 1]);
      length += l;
      radius_integral += 0.5 * l * (c.radius[p[i]] + c.radius[p[i + 1]]);
    }
    const double diameter = 2 * u * radius_integral / length;
    const std::string where = path + ": vessel " + std::to_string(k) + " (polyline " + std::to_string(chains[k].cell) +
                              ", point " + std::to_string(p.front()) + " to point " + std::to_string(p.back()) + "): ";
    if (!ranges::length.contains(u * length)) throw SettingError("unit", where + out_of_range("length", ranges::length, u * length) + unit_hint);
    if (!ranges::diameter.contains(diameter)) throw SettingError("unit", where + out_of_range("diameter", ranges::diameter, diameter) + unit_hint);
    for (std::size_t end : {p.front(), p.back()})
      for (int d = 0; d < 3; ++d)
        if (!ranges::coordinate.contains(u * c.xyz[3 * end + d]))
          throw SettingError("unit", where + out_of_range(axis_name[d], ranges::coordinate, u * c.xyz[3 * end + d]) + unit_hint);
    net.add_vessel(static_cast<std::int64_t>(k), node_of[p.front()], node_of[p.back()], u * length, diameter,
                   std::nan(""), std::nan(""), 0);
  }
  net.generation = generations_from_inlets(net);  // breadth first from the nodes no vessel enters

  // How many separate pieces: polylines that share no point with the rest.
  UnionFind parts(net.node_count());
  for (std::size_t v = 0; v < net.vessel_count(); ++v)
    parts.join(static_cast<std::size_t>(net.from[v]), static_cast<std::size_t>(net.to[v]));
  std::size_t pieces = 0;
  for (std::size_t i = 0; i < net.node_count(); ++i) pieces += parts.find(i) == i;

  net.provenance = {{"tool", "vimport"}, {"format", "vtk-centerline"}, {"source", path},
                    {"radius_array", co.radius_array}, {"length_unit_m", u}};
  options.note("read " + plural(c.cell_count(), "polyline", "polylines") + " of " +
               plural(c.point_count(), "point", "points") + " as " + plural(net.vessel_count(), "vessel", "vessels") +
               " between " + plural(net.node_count(), "node", "nodes") + "; coordinates and radii (" + co.radius_array +
               ") in units of " + format_number(u) + " m");
  options.note("vessel diameter: twice the length-weighted mean of the radius along each chain; lengths: "
               "the chain's arc length");
  if (coincident > 0)
    options.note("joined " + plural(coincident, "point", "points") + " lying on another point (within 1e-9 of the model's size)");
  if (overlapping > 0)
    options.note("merged " + plural(overlapping, "segment", "segments") + " that several polylines share");
  if (repeated_points > 0)
    options.note("skipped " + plural(repeated_points, "repeated point", "repeated points") + " within polylines");
  if (single_point_cells > 0)
    options.note("ignored " + plural(single_point_cells, "polyline", "polylines") + " of fewer than two points");
  if (c.vertices > 0) options.note("ignored " + plural(c.vertices, "vertex cell", "vertex cells"));
  std::vector<std::string> other_point_arrays;
  for (const auto& a : c.point_arrays)
    if (a != co.radius_array) other_point_arrays.push_back(a);
  if (!other_point_arrays.empty()) options.note("point data not imported: " + join(other_point_arrays));
  if (!c.cell_arrays.empty()) options.note("cell data not imported: " + join(c.cell_arrays));
  if (pieces > 1) options.note("the centerlines form " + std::to_string(pieces) + " separate pieces that share no point");
  fill_missing_walls(net, options);
  return net;
}

}  // namespace

Network read_vtk_centerline(const std::string& path, const ImportOptions& options, const CenterlineOptions& centerline) {
  if (!(centerline.length_unit > 0) || !std::isfinite(centerline.length_unit))
    throw InputError(path + ": the length unit must be a positive number of metres (got " +
                     format_number(centerline.length_unit) + ")");
  std::string text = read_whole_file(path);
  std::size_t start = 0;
  if (text.rfind("\xEF\xBB\xBF", 0) == 0) start = 3;  // a UTF-8 byte order mark
  while (start < text.size() && is_space(text[start])) ++start;
  Centerlines c;
  if (text.compare(start, 14, "# vtk DataFile") == 0) c = LegacyReader(path, text.substr(start)).read(centerline);
  else if (text.compare(start, 1, "<") == 0) c = read_xml(path, std::move(text), centerline);
  else throw InputError(path + ": neither VTK XML (.vtp) nor a legacy VTK file ('# vtk DataFile ...')");
  return build_network(path, c, options, centerline);
}

}  // namespace hemotree
