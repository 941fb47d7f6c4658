// T. W. Secomb's network.dat, laid out as NetFlow reads it (input.cpp): a title line, five
// lines of global numbers, the segment count, a line of column names, the segments, the node
// count, column names, the nodes, the boundary-node count, column names, the boundary nodes.
// Every line is checked as it is read, so a malformed file is refused at its line.
#include "exchange/secomb.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "core/errors.hpp"
#include "formats/field_ranges.hpp"

namespace hemotree {

namespace {

constexpr double metre_per_um = 1e-6;
// The conventional millimetre of mercury: 13.5951 g/cm^3 x 9.80665 m/s^2 x 1 mm.
constexpr double pascal_per_mmhg = 133.322387415;
constexpr double m3s_per_nl_min = 1e-12 / 60.0;

// NetFlow ignores segments of other types (its flow.cpp and analyzenet.cpp test for 4 or 5).
bool is_flowing(std::int64_t type) { return type == 4 || type == 5; }

// ---- the file's lines and fields ---------------------------------------------------------

// A field as a message shows it: quoted, at most 40 characters, control bytes as '?', so
// that the message stays one printable line whatever the file holds.
std::string quoted(std::string_view text) {
  std::string s = "'";
  for (char c : text.substr(0, 40)) s += static_cast<unsigned char>(c) < 0x20 || c == 0x7f ? '?' : c;
  return s + (text.size() > 40 ? "...'" : "'");
}

// Decimal integers only: NetFlow reads names with scanf's %i, which takes a leading 0 for
// octal ("010" is 8) and 0x for hexadecimal, so such names are refused rather than guessed.
std::optional<std::int64_t> to_integer(std::string_view s) {
  const std::string_view digits = !s.empty() && (s[0] == '-' || s[0] == '+') ? s.substr(1) : s;
  if (digits.size() > 1 && digits[0] == '0') return std::nullopt;
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  std::int64_t value = 0;
  const auto [end, error] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (error != std::errc() || end != s.data() + s.size() || s.empty()) return std::nullopt;
  return value;
}

std::optional<double> to_real(std::string_view s) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  double value = 0;
  const auto [end, error] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (error != std::errc() || end != s.data() + s.size() || s.empty() || !std::isfinite(value))
    return std::nullopt;
  return value;
}

// The file's lines in order, each split into fields at blanks and tabs (and a Windows
// line end's '\r'); errors are "FILE:LINE: what is wrong".
class Lines {
 public:
  explicit Lines(const std::string& path) : path_(path), in_(path) {
    std::error_code error;
    if (std::filesystem::is_directory(path, error)) throw IoError("cannot read " + path + ": a directory");
    if (!in_) throw IoError("cannot open " + path);
  }

  // Moves to the next line, blank lines skipped (scanf skips them between numbers too);
  // false at the end of the file.
  bool next(bool skip_blank = true) {
    while (std::getline(in_, text_)) {
      ++number_;
      split();
      if (!skip_blank || !fields_.empty()) return true;
    }
    if (in_.bad() || !in_.eof()) throw IoError("cannot read " + path_);
    fields_.clear();
    return false;
  }
  // As next(), but the end of the file is an error saying what was expected.
  void expect(const std::string& what) {
    if (!next()) throw InputError(path_ + ":" + std::to_string(number_) + ": the file ends where " + what + " should follow");
  }

  int number() const { return number_; }
  const std::vector<std::string_view>& fields() const { return fields_; }
  const std::string& path() const { return path_; }
  [[noreturn]] void fail(const std::string& what) const { fail_at(number_, what); }
  [[noreturn]] void fail_at(int line, const std::string& what) const {
    throw InputError(path_ + ":" + std::to_string(line) + ": " + what);
  }

  std::int64_t integer(std::size_t k, const std::string& what) const {
    if (k >= fields_.size()) fail(what + " is missing");
    const auto v = to_integer(fields_[k]);
    if (!v) fail(what + " must be a decimal integer (got " + quoted(fields_[k]) + ")");
    return *v;
  }
  double real(std::size_t k, const std::string& what) const {
    if (k >= fields_.size()) fail(what + " is missing");
    const auto v = to_real(fields_[k]);
    if (!v) fail(what + " must be a number (got " + quoted(fields_[k]) + ")");
    return *v;
  }
  // A count line: a non-negative integer first, words after it.
  std::int64_t count(const std::string& what) const {
    const std::int64_t n = integer(0, "the " + what);
    if (n < 0 || n > std::numeric_limits<std::int32_t>::max())
      fail("the " + what + " must lie in [0, 2147483647] (got " + std::to_string(n) + ")");
    return n;
  }
  // NetFlow skips the line after each count unread: it must hold column names, not data
  // (a missing names line would make NetFlow skip the first segment, node or boundary node).
  void column_names(const std::string& section, const std::string& names) {
    expect("the " + section + "' column names (" + names + ")");
    if (to_real(fields_[0]))
      fail("expected the " + section + "' column names (" + names + ") after the count, found numbers; "
           "NetFlow skips this line unread");
  }

 private:
  void split() {
    fields_.clear();
    std::string_view s(text_);
    std::size_t k = 0;
    const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; };
    while (k < s.size()) {
      while (k < s.size() && blank(s[k])) ++k;
      const std::size_t start = k;
      while (k < s.size() && !blank(s[k])) ++k;
      if (k > start) fields_.push_back(s.substr(start, k - start));
    }
  }

  std::string path_;
  std::ifstream in_;
  std::string text_;
  std::vector<std::string_view> fields_;
  int number_ = 0;
};

// ---- what the file holds -----------------------------------------------------------------

struct Segment {
  int line;
  std::int64_t name, type, from, to;
  double diameter_um;
};

struct Node {
  int line;
  std::int64_t name;
  double x_um, y_um, z_um;
};

struct BoundaryNode {
  int line;
  std::int64_t name, type;
  double value, hematocrit;
};

// The five lines of global parameters before the segment count: NetFlow reads them as
// numbers and ignores them (Greens uses them); checked here so that a file of another layout
// is refused at its first odd line instead of at a segment that is not one.
void read_header(Lines& lines) {
  lines.expect("the box dimensions [um]");
  for (std::size_t k = 0; k < 3; ++k) lines.real(k, "the box dimensions (three numbers [um])");
  lines.expect("the numbers of tissue points in x, y, z");
  for (std::size_t k = 0; k < 3; ++k)
    lines.integer(k, "the numbers of tissue points (three integers)");
  lines.expect("the outer bound distance [um]");
  lines.real(0, "the outer bound distance [um]");
  lines.expect("the maximum segment length [um]");
  lines.real(0, "the maximum segment length [um]");
  lines.expect("the maximum number of segments per node");
  lines.integer(0, "the maximum number of segments per node");
}

// A line of seven or more numbers where a count belongs is a segment the count left out.
void refuse_segment_as_count(const Lines& lines, int count_line, std::int64_t segments) {
  if (lines.fields().size() >= 7 &&
      std::all_of(lines.fields().begin(), lines.fields().begin() + 7, [](auto f) { return to_real(f).has_value(); }))
    lines.fail("a segment line where the number of nodes should be: line " + std::to_string(count_line) +
               " announced " + std::to_string(segments) + " segments, the file has more");
}

// Room for a section's announced count, but no more than a million lines ahead: a corrupt
// count must not allocate gigabytes before the file shows it wrong.
std::size_t expected(std::int64_t count) { return static_cast<std::size_t>(std::min<std::int64_t>(count, 1 << 20)); }

std::string range_message(const std::string& what, double got, double min, double max, const char* unit) {
  return what + " must lie in [" + format_number(min) + ", " + format_number(max) + "] " + unit + " (got " +
         format_number(got) + ")";
}

std::vector<Segment> read_segments(Lines& lines, std::size_t& nonzero_results, int& count_line) {
  lines.expect("the total number of segments");
  count_line = lines.number();
  const std::int64_t count = lines.count("total number of segments");
  lines.column_names("segments", "SegName Type StartNode EndNode Diam Flow Hd");
  std::vector<Segment> segments;
  segments.reserve(expected(count));
  std::unordered_map<std::int64_t, int> seen;
  const FieldRange& d = ranges::diameter;
  for (std::int64_t k = 0; k < count; ++k) {
    if (!lines.next())
      lines.fail("the file ends after " + std::to_string(k) + " of the " + std::to_string(count) +
                 " segments announced on line " + std::to_string(count_line));
    Segment s{lines.number(), 0, 0, 0, 0, 0};
    const std::string of = " (segment " + std::to_string(k + 1) + " of the " + std::to_string(count) +
                           " announced on line " + std::to_string(count_line) + ")";
    if (lines.fields().size() < 7)
      lines.fail("a segment line needs 7 fields: name, type, from node, to node, diameter [um], flow [nl/min], "
                 "hematocrit; found " + std::to_string(lines.fields().size()) + of);
    s.name = lines.integer(0, "the segment name" + of);
    s.type = lines.integer(1, "segment " + std::to_string(s.name) + ": the type");
    s.from = lines.integer(2, "segment " + std::to_string(s.name) + ": the start node");
    s.to = lines.integer(3, "segment " + std::to_string(s.name) + ": the end node");
    s.diameter_um = lines.real(4, "segment " + std::to_string(s.name) + ": the diameter");
    const double flow = lines.real(5, "segment " + std::to_string(s.name) + ": the flow");
    const double hd = lines.real(6, "segment " + std::to_string(s.name) + ": the hematocrit");
    if (flow != 0 || hd != 0) ++nonzero_results;
    if (const auto [at, fresh] = seen.emplace(s.name, s.line); !fresh)
      lines.fail("segment " + std::to_string(s.name) + " appears twice (first on line " + std::to_string(at->second) + ")");
    if (is_flowing(s.type) && !d.contains(s.diameter_um * metre_per_um))
      lines.fail("segment " + std::to_string(s.name) + ": " +
                 range_message("the diameter", s.diameter_um, d.min / metre_per_um, d.max / metre_per_um, "um"));
    if (is_flowing(s.type) && s.from == s.to)
      lines.fail("segment " + std::to_string(s.name) + " joins node " + std::to_string(s.from) +
                 " to itself (zero length)");
    segments.push_back(s);
  }
  return segments;
}

std::vector<Node> read_nodes(Lines& lines, std::int64_t segment_count, int segment_count_line) {
  lines.expect("the number of nodes");
  refuse_segment_as_count(lines, segment_count_line, segment_count);
  const int count_line = lines.number();
  const std::int64_t count = lines.count("number of nodes");
  lines.column_names("nodes", "Name x y z");
  std::vector<Node> nodes;
  nodes.reserve(expected(count));
  std::unordered_map<std::int64_t, int> seen;
  const double limit = ranges::coordinate.max / metre_per_um;
  for (std::int64_t k = 0; k < count; ++k) {
    if (!lines.next())
      lines.fail("the file ends after " + std::to_string(k) + " of the " + std::to_string(count) +
                 " nodes announced on line " + std::to_string(count_line));
    const std::string of = " (node " + std::to_string(k + 1) + " of the " + std::to_string(count) +
                           " announced on line " + std::to_string(count_line) + ")";
    if (lines.fields().size() < 4)
      lines.fail("a node line needs 4 fields: name, x, y, z [um]; found " + std::to_string(lines.fields().size()) + of);
    Node n{lines.number(), lines.integer(0, "the node name" + of), 0, 0, 0};
    const std::string node = "node " + std::to_string(n.name);
    n.x_um = lines.real(1, node + ": x");
    n.y_um = lines.real(2, node + ": y");
    n.z_um = lines.real(3, node + ": z");
    for (const auto& [axis, value] : {std::pair{"x", n.x_um}, std::pair{"y", n.y_um}, std::pair{"z", n.z_um}})
      if (!(std::abs(value) <= limit)) lines.fail(node + ": " + range_message(axis, value, -limit, limit, "um"));
    if (const auto [at, fresh] = seen.emplace(n.name, n.line); !fresh)
      lines.fail(node + " appears twice (first on line " + std::to_string(at->second) + ")");
    nodes.push_back(n);
  }
  return nodes;
}

std::vector<BoundaryNode> read_boundary_nodes(Lines& lines, std::size_t& solute_columns) {
  lines.expect("the total number of boundary nodes");
  const int count_line = lines.number();
  const std::int64_t count = lines.count("total number of boundary nodes");
  lines.column_names("boundary nodes", "Node Bctype Press/Flow HD");
  std::vector<BoundaryNode> boundaries;
  boundaries.reserve(expected(count));
  std::unordered_map<std::int64_t, int> seen;
  for (std::int64_t k = 0; k < count; ++k) {
    if (!lines.next())
      lines.fail("the file ends after " + std::to_string(k) + " of the " + std::to_string(count) +
                 " boundary nodes announced on line " + std::to_string(count_line));
    const std::string of = " (boundary node " + std::to_string(k + 1) + " of the " + std::to_string(count) +
                           " announced on line " + std::to_string(count_line) + ")";
    if (lines.fields().size() < 4)
      lines.fail("a boundary node line needs 4 fields: name, bctype, pressure [mmHg] or flow [nl/min], "
                 "hematocrit; found " + std::to_string(lines.fields().size()) + of);
    BoundaryNode b{lines.number(), lines.integer(0, "the boundary node's name" + of), 0, 0, 0};
    const std::string node = "boundary node " + std::to_string(b.name);
    b.type = lines.integer(1, node + ": bctype");
    if (b.type != 0 && b.type != 2)
      lines.fail(node + ": bctype " + std::to_string(b.type) +
                 " is not one NetFlow defines (0: pressure [mmHg], 2: inflow [nl/min], negative for an outflow)");
    b.value = lines.real(2, node + (b.type == 0 ? ": the pressure" : ": the flow"));
    b.hematocrit = lines.real(3, node + ": the hematocrit");
    if (b.type == 0 && !ranges::pressure.contains(b.value * pascal_per_mmhg))
      lines.fail(node + ": " + range_message("the pressure", b.value, ranges::pressure.min / pascal_per_mmhg,
                                             ranges::pressure.max / pascal_per_mmhg, "mmHg"));
    if (b.type == 2 && !ranges::flow_sample.contains(b.value * m3s_per_nl_min))
      lines.fail(node + ": " + range_message("the flow", b.value, ranges::flow_sample.min / m3s_per_nl_min,
                                             ranges::flow_sample.max / m3s_per_nl_min, "nl/min"));
    // NetFlow ignores the hematocrit of an outflow; where blood may enter it is a condition.
    // An inflow is one whose flow in m^3/s is positive: 1e-320 nl/min is 0 m^3/s.
    const bool may_enter = b.type == 0 || b.value * m3s_per_nl_min > 0;
    if (may_enter && !ranges::hematocrit.contains(b.hematocrit))
      lines.fail(node + ": " + range_message("the hematocrit", b.hematocrit, ranges::hematocrit.min,
                                             ranges::hematocrit.max, "(discharge, inflowing blood)"));
    if (lines.fields().size() > 4) ++solute_columns;
    if (const auto [at, fresh] = seen.emplace(b.name, b.line); !fresh)
      lines.fail(node + " appears twice (first on line " + std::to_string(at->second) + ")");
    boundaries.push_back(b);
  }
  return boundaries;
}

// ---- generations --------------------------------------------------------------------------

// network.dat has no generations and its networks have loops, so the rule of trees (counted
// along the flow from the inlets) does not apply: a vessel's generation here is the number
// of vessels between it and the nearest root node, along vessels in either direction
// (breadth first), roots at generation 0. A part of the network that no root reaches is
// counted from its first node. Every generation is below the vessel count, as the format
// requires. Returns the number of parts counted without a root.
std::size_t set_generations(Network& net, const std::vector<std::int32_t>& roots) {
  const std::size_t nodes = net.node_count();
  std::vector<std::int64_t> offset(nodes + 1, 0);
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    ++offset[static_cast<std::size_t>(net.from[v]) + 1];
    ++offset[static_cast<std::size_t>(net.to[v]) + 1];
  }
  for (std::size_t n = 0; n < nodes; ++n) offset[n + 1] += offset[n];
  std::vector<std::int32_t> neighbour(static_cast<std::size_t>(offset[nodes]));
  std::vector<std::int64_t> fill(offset.begin(), offset.end() - 1);
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    neighbour[static_cast<std::size_t>(fill[static_cast<std::size_t>(net.from[v])]++)] = net.to[v];
    neighbour[static_cast<std::size_t>(fill[static_cast<std::size_t>(net.to[v])]++)] = net.from[v];
  }

  std::vector<std::int32_t> distance(nodes, -1), queue;
  queue.reserve(nodes);
  const auto spread = [&](std::size_t head) {
    for (; head < queue.size(); ++head) {
      const auto n = static_cast<std::size_t>(queue[head]);
      for (auto k = offset[n]; k < offset[n + 1]; ++k) {
        const auto m = static_cast<std::size_t>(neighbour[static_cast<std::size_t>(k)]);
        if (distance[m] < 0) {
          distance[m] = distance[n] + 1;
          queue.push_back(static_cast<std::int32_t>(m));
        }
      }
    }
  };
  for (std::int32_t r : roots)
    if (distance[static_cast<std::size_t>(r)] < 0) {
      distance[static_cast<std::size_t>(r)] = 0;
      queue.push_back(r);
    }
  spread(0);
  std::size_t rootless = 0;
  for (std::size_t n = 0; n < nodes; ++n)
    if (distance[n] < 0) {
      ++rootless;
      distance[n] = 0;
      const std::size_t head = queue.size();
      queue.push_back(static_cast<std::int32_t>(n));
      spread(head);
    }
  for (std::size_t v = 0; v < net.vessel_count(); ++v)
    net.generation[v] = std::min(distance[static_cast<std::size_t>(net.from[v])],
                                 distance[static_cast<std::size_t>(net.to[v])]);
  return rootless;
}

std::string plural(std::size_t n, const std::string& one, const std::string& many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

// The first few names of a list, for a note: "17, 18, 19 and 4 more".
std::string some_names(const std::vector<std::int64_t>& names) {
  std::string s;
  const std::size_t shown = std::min<std::size_t>(names.size(), 5);
  for (std::size_t k = 0; k < shown; ++k) s += (k ? ", " : "") + std::to_string(names[k]);
  if (names.size() > shown) s += " and " + std::to_string(names.size() - shown) + " more";
  return s;
}

// The title line for the provenance: printable ASCII only, so that it is valid JSON text.
std::string printable(const std::string& title) {
  std::string s;
  for (char c : title)
    if (c >= 0x20 && c < 0x7f) s += c;
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

}  // namespace

Network read_secomb(const std::string& path, const ImportOptions& options) {
  Lines lines(path);
  if (!lines.next(false)) throw InputError(path + ": empty file (network.dat begins with a title line)");
  std::string title;
  for (auto f : lines.fields()) title += std::string(title.empty() ? "" : " ") + std::string(f);
  read_header(lines);
  std::size_t nonzero_results = 0, solute_columns = 0;
  int segment_count_line = 0;
  const std::vector<Segment> segments = read_segments(lines, nonzero_results, segment_count_line);
  const std::vector<Node> nodes = read_nodes(lines, static_cast<std::int64_t>(segments.size()), segment_count_line);
  const std::vector<BoundaryNode> boundary_nodes = read_boundary_nodes(lines, solute_columns);
  int trailing_from = 0;
  std::size_t trailing = 0;
  while (lines.next()) {
    if (trailing++ == 0) trailing_from = lines.number();
  }

  // Nodes: those that a flowing segment joins, in the file's order.
  std::unordered_map<std::int64_t, std::size_t> node_at;  // name -> position in `nodes`
  for (std::size_t k = 0; k < nodes.size(); ++k) node_at.emplace(nodes[k].name, k);
  std::vector<char> used(nodes.size(), 0);
  std::vector<std::int64_t> skipped;
  for (const Segment& s : segments) {
    if (!is_flowing(s.type)) {
      skipped.push_back(s.name);
      continue;
    }
    for (std::int64_t end : {s.from, s.to}) {
      const auto at = node_at.find(end);
      if (at == node_at.end())
        lines.fail_at(s.line, "segment " + std::to_string(s.name) + ": node " + std::to_string(end) +
                                  " is not in the node list");
      used[at->second] = 1;
    }
  }
  if (skipped.size() == segments.size())
    throw InputError(path + ": no segment of type 4 or 5 (the only types NetFlow computes flow in)");

  Network net;
  net.reserve(segments.size() - skipped.size(), nodes.size());
  std::vector<std::int32_t> index_of(nodes.size(), -1);
  std::vector<std::int64_t> unused;
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    if (!used[k]) {
      unused.push_back(nodes[k].name);
      continue;
    }
    index_of[k] = net.add_node(nodes[k].name, nodes[k].x_um * metre_per_um, nodes[k].y_um * metre_per_um,
                               nodes[k].z_um * metre_per_um);
  }

  // Vessels: NetFlow's lengths, the straight distance between the nodes.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const Segment& s : segments) {
    if (!is_flowing(s.type)) continue;
    const Node& a = nodes[node_at.at(s.from)];
    const Node& b = nodes[node_at.at(s.to)];
    const double length_um = std::hypot(b.x_um - a.x_um, b.y_um - a.y_um, b.z_um - a.z_um);
    const std::string segment = "segment " + std::to_string(s.name);
    if (length_um == 0)
      lines.fail_at(s.line, segment + " has zero length: its nodes " + std::to_string(s.from) + " and " +
                                std::to_string(s.to) + " lie at the same point");
    if (!ranges::length.contains(length_um * metre_per_um))
      lines.fail_at(s.line, segment + ": " + range_message("the length (the distance between its nodes)", length_um,
                                                           ranges::length.min / metre_per_um,
                                                           ranges::length.max / metre_per_um, "um"));
    net.add_vessel(s.name, index_of[node_at.at(s.from)], index_of[node_at.at(s.to)], length_um * metre_per_um,
                   s.diameter_um * metre_per_um, nan, nan, 0);
  }

  // Boundary nodes: pressures and flows into the network, as NetFlow's solve.cpp takes them
  // (a positive flow raises the node's pressure above its neighbour's: blood enters).
  std::vector<std::int32_t> inflows, all_boundaries;
  std::size_t pressures = 0, inflow_count = 0, outflows = 0;
  for (const BoundaryNode& bn : boundary_nodes) {
    const std::string node = "boundary node " + std::to_string(bn.name);
    const auto at = node_at.find(bn.name);
    if (at == node_at.end()) lines.fail_at(bn.line, node + " is not in the node list");
    if (!used[at->second]) lines.fail_at(bn.line, node + ": no segment of type 4 or 5 joins it");
    NodeBoundary b;
    b.node = index_of[at->second];
    if (bn.type == 0) {
      b.type = BoundaryType::pressure;
      b.waveform = Waveform::constant_value(bn.value * pascal_per_mmhg);
      b.hematocrit = bn.hematocrit;
      ++pressures;
    } else {
      b.type = BoundaryType::flow;
      b.waveform = Waveform::constant_value(bn.value * m3s_per_nl_min);
      if (bn.value * m3s_per_nl_min > 0) {  // as the network holds it (below 3e-310 nl/min, 0)
        b.hematocrit = bn.hematocrit;
        inflows.push_back(b.node);
        ++inflow_count;
      } else {
        ++outflows;
      }
    }
    all_boundaries.push_back(b.node);
    net.boundaries.push_back(b);
  }
  std::sort(net.boundaries.begin(), net.boundaries.end(),
            [](const NodeBoundary& p, const NodeBoundary& q) { return p.node < q.node; });

  const std::size_t rootless = set_generations(net, inflows.empty() ? all_boundaries : inflows);

  net.provenance = {{"tool", "vimport"}, {"format", "secomb"}, {"source", path}, {"title", printable(title)}};

  options.note("read " + plural(net.vessel_count(), "segment", "segments") + ", " +
               plural(net.node_count(), "node", "nodes") + " and " +
               plural(boundary_nodes.size(), "boundary node", "boundary nodes") + " (" +
               std::to_string(pressures) + " pressure, " + std::to_string(inflow_count) + " inflow, " +
               std::to_string(outflows) + " outflow or closed)");
  if (!skipped.empty())
    options.note("skipped " + plural(skipped.size(), "segment", "segments") +
                 " of a type other than 4 or 5, as NetFlow does: " + some_names(skipped));
  if (!unused.empty())
    options.note("left out " + plural(unused.size(), "node", "nodes") +
                 " that no segment of type 4 or 5 joins: " + some_names(unused));
  if (nonzero_results > 0)
    options.note("ignored the flow and hematocrit columns of " + plural(nonzero_results, "segment", "segments") +
                 ": NetFlow's results, not its input");
  if (solute_columns > 0)
    options.note("ignored the solute columns (PO2, ...) of " +
                 plural(solute_columns, "boundary node", "boundary nodes") + ": hemotree models no solutes");
  if (trailing > 0)
    options.note("ignored " + plural(trailing, "line", "lines") + " after the last boundary node (from line " +
                 std::to_string(trailing_from) + ")");
  options.note("generations counted breadth first from the " +
               std::string(inflows.empty() ? "boundary nodes" : "inflow boundary nodes") +
               " along vessels in either direction (network.dat has none, and its networks may loop)");
  if (rootless > 0)
    options.note(plural(rootless, "part", "parts") + " of the network joined to no boundary node " +
                 "(NetFlow cannot compute flow there), counted from " + (rootless == 1 ? "its" : "their") +
                 " first node");
  fill_missing_walls(net, options);
  return net;
}

// ---- writing --------------------------------------------------------------------------------

namespace {

std::string vessel_name(const Network& net, std::size_t v) { return "vessel " + std::to_string(net.id[v]); }
std::string node_name(const Network& net, std::size_t n) { return "node " + std::to_string(net.node_id[n]); }

// Names must fit NetFlow's int (scanf %i).
void check_name(std::int64_t id, const std::string& what) {
  if (id < std::numeric_limits<std::int32_t>::min() || id > std::numeric_limits<std::int32_t>::max())
    throw InputError(what + ": network.dat names are 32-bit integers (NetFlow reads them with %i); "
                            "this id does not fit");
}

// A coordinate in um with six decimals.
std::string micrometres(double metres) {
  char text[64];
  const int n = std::snprintf(text, sizeof text, "%.6f", metres / metre_per_um);
  return std::string(text, static_cast<std::size_t>(n));
}

// Everything network.dat cannot hold is refused before a byte is written.
void check_writable(const Network& net, const std::vector<NodeBoundary>& boundaries,
                    const std::vector<std::int32_t>& degree) {
  if (!net.has_coordinates())
    throw InputError("the network has no node coordinates, and network.dat gives each segment's length as the "
                     "distance between its nodes (NetFlow computes it so): nothing to write");
  if (net.vessel_count() == 0) throw InputError("the network has no vessels");
  for (std::size_t n = 0; n < net.node_count(); ++n) check_name(net.node_id[n], node_name(net, n));
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    check_name(net.id[v], vessel_name(net, v));
    if (net.is_tapered(v))
      throw InputError(vessel_name(net, v) + " tapers, and network.dat holds one diameter a segment");
    const auto f = static_cast<std::size_t>(net.from[v]), t = static_cast<std::size_t>(net.to[v]);
    const double distance = std::hypot(net.x[t] - net.x[f], net.y[t] - net.y[f], net.z[t] - net.z[f]);
    // Beyond the rounding of lengths and coordinates to 9 significant digits (vnet files):
    // a curved vessel. A coordinate far from the origin rounds by more than a short vessel's
    // length would, hence the term in the coordinates' size.
    const double size = std::max({std::abs(net.x[f]), std::abs(net.y[f]), std::abs(net.z[f]), std::abs(net.x[t]),
                                  std::abs(net.y[t]), std::abs(net.z[t])});
    if (!(std::abs(distance - net.length[v]) <= 1e-5 * net.length[v] + 2e-8 * size))
      throw InputError(vessel_name(net, v) + ": length " + format_number(net.length[v] / metre_per_um) +
                       " um differs from the distance between its nodes (" + format_number(distance / metre_per_um) +
                       " um), and NetFlow takes lengths from the coordinates");
  }
  for (const NodeBoundary& b : boundaries) {
    const std::string node = node_name(net, static_cast<std::size_t>(b.node));
    if (b.is_outlet())
      throw InputError(node + ": an outlet model (" + std::string(to_string(b.type)) +
                       ") cannot be written to network.dat, which holds pressures and flows only");
    if (b.waveform.shape != Waveform::Shape::constant)
      throw InputError(node + ": a time-varying " + std::string(to_string(b.type)) +
                       " cannot be written to network.dat, which holds steady values only");
    if (degree[static_cast<std::size_t>(b.node)] != 1)
      throw InputError(node + ": a boundary where " + std::to_string(degree[static_cast<std::size_t>(b.node)]) +
                       " vessels meet; NetFlow takes boundary nodes at the end of one segment");
  }
}

}  // namespace

void write_secomb(const Network& net, OutputStream& out) {
  const std::vector<NodeBoundary> boundaries = node_boundaries(net);
  std::vector<std::int32_t> degree(net.node_count(), 0);
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    ++degree[static_cast<std::size_t>(net.from[v])];
    ++degree[static_cast<std::size_t>(net.to[v])];
  }
  check_writable(net, boundaries, degree);

  // Lines 2-6 are Greens's tissue parameters, which NetFlow reads and ignores: the nodes'
  // extent, one tissue point, the maximum segment length and the maximum node degree (the
  // last sizes NetFlow's arrays, so it must be right).
  const auto extent = [](const std::vector<double>& c) {
    const auto [lo, hi] = std::minmax_element(c.begin(), c.end());
    return (*hi - *lo) / metre_per_um;
  };
  const double longest = *std::max_element(net.length.begin(), net.length.end()) / metre_per_um;
  out << "Network written by hemotree: " << static_cast<long long>(net.vessel_count()) << " segments, "
      << static_cast<long long>(net.node_count()) << " nodes\n";
  out << extent(net.x) << ' ' << extent(net.y) << ' ' << extent(net.z) << " box dimensions in microns\n";
  out << "1 1 1 number of tissue points in x,y,z directions\n";
  out << "100 outer bound distance\n";
  out << longest << " max. segment length\n";
  out << *std::max_element(degree.begin(), degree.end()) << " maximum number of segments per node\n";
  out << static_cast<long long>(net.vessel_count()) << " total number of segments\n";
  out << "SegName Type StartNode EndNode Diam Flow[nl/min] Hd\n";
  for (std::size_t v = 0; v < net.vessel_count(); ++v)
    out << static_cast<long long>(net.id[v]) << " 5 " << static_cast<long long>(net.node_id[static_cast<std::size_t>(net.from[v])])
        << ' ' << static_cast<long long>(net.node_id[static_cast<std::size_t>(net.to[v])]) << ' '
        << net.diameter[v] / metre_per_um << " 0 0\n";
  out << static_cast<long long>(net.node_count()) << " number of nodes\n";
  out << "Name x y z\n";
  // Coordinates to a picometre, as Secomb's files give them (%f): lengths follow from their
  // differences, which 9 significant digits of a far coordinate would blur.
  for (std::size_t n = 0; n < net.node_count(); ++n)
    out << static_cast<long long>(net.node_id[n]) << ' ' << micrometres(net.x[n]) << ' ' << micrometres(net.y[n])
        << ' ' << micrometres(net.z[n]) << '\n';
  // Hematocrit where blood may enter: the boundary's own, else the blood's discharge value.
  const double blood_hematocrit = net.blood ? net.blood->hematocrit : Blood{}.hematocrit;
  out << static_cast<long long>(boundaries.size()) << " total number of boundary nodes\n";
  out << "Node Bctype Press/Flow HD\n";
  for (const NodeBoundary& b : boundaries) {
    const bool pressure = b.type == BoundaryType::pressure;
    out << static_cast<long long>(net.node_id[static_cast<std::size_t>(b.node)]) << (pressure ? " 0 " : " 2 ")
        << (pressure ? b.waveform.mean / pascal_per_mmhg : b.waveform.mean / m3s_per_nl_min) << ' '
        << (std::isnan(b.hematocrit) ? blood_hematocrit : b.hematocrit) << '\n';
  }
}

}  // namespace hemotree
