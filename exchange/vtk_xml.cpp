// VTK XML PolyData (.vtp) read into Centerlines. XML goes through Boost.PropertyTree once the
// appended data, raw bytes that are not XML, is cut out; each DataArray is decoded from ascii
// text, base64 (inline or appended) or raw appended bytes, each optionally zlib-compressed in
// VTK's blocks.
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
#include "exchange/vtk_centerline_file.hpp"

namespace hemotree::vtk {

namespace {

using boost::property_tree::ptree;

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
}  // namespace

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
}  // namespace hemotree::vtk
