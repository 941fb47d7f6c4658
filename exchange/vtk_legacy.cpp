// Legacy ASCII VTK PolyData (.vtk) read into Centerlines, with the file's line in every message.
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


#include "core/errors.hpp"
#include "core/setting_error.hpp"
#include "formats/field_ranges.hpp"
#include "exchange/vtk_centerline_file.hpp"

namespace hemotree::vtk {

namespace {

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
}  // namespace

Centerlines read_legacy(const std::string& path, std::string text, const CenterlineOptions& options) {
  return LegacyReader(path, std::move(text)).read(options);
}

}  // namespace hemotree::vtk
