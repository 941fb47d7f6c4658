// VTK centerlines: the file is read into points, a radius per point and polylines
// (Centerlines, vtk_centerline_file.hpp), whatever the encoding; the network is then built from
// that geometry alone, here.
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


#include "core/errors.hpp"
#include "core/setting_error.hpp"
#include "formats/field_ranges.hpp"
#include "formats/topology.hpp"
#include "exchange/vtk_centerline_file.hpp"

namespace hemotree {

namespace vtk {

namespace {

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

// Every point at a finite place with a positive radius; GroupIds (vmtkbranchextractor's tracts),
// where given, one per polyline.
void check_points(const std::string& path, const Centerlines& c, const CenterlineOptions& co) {
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
}

// Segments, each once: overlapping polylines through the same points give it twice.
struct Segments {
  std::vector<Segment> unique;
  std::size_t overlapping, repeated_points, single_point_cells;  // merged, skipped, ignored
};

Segments unique_segments(const std::string& path, const Centerlines& c, UnionFind& same) {
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
  return {std::move(unique), overlapping, repeated_points, single_point_cells};
}

// Segments at each point (CSR): at[first[p] .. first[p + 1]); nodes are the points where one or
// three and more meet.
struct Incidence {
  std::vector<std::size_t> first, at;
  std::size_t degree(std::size_t p) const { return first[p + 1] - first[p]; }
};

Incidence incidence(std::size_t n, const std::vector<Segment>& unique) {
  std::vector<std::size_t> first(n + 1, 0), at(2 * unique.size());
  for (const Segment& s : unique) ++first[s.a + 1], ++first[s.b + 1];
  for (std::size_t p = 0; p < n; ++p) first[p + 1] += first[p];
  std::vector<std::size_t> fill(first.begin(), first.end() - 1);
  for (std::size_t s = 0; s < unique.size(); ++s) at[fill[unique[s].a]++] = at[fill[unique[s].b]++] = s;
  return {std::move(first), std::move(at)};
}

// vmtkcenterlines writes one centerline from the inlet to each outlet: they run side by
// side along common trunks without sharing points. Such pieces leave a point together: at
// two radii from it they are still within 5% of a radius of each other, where the
// daughters of any real bifurcation (20 degrees apart or more) are 0.7 radii apart.
// Checked wherever pieces meet: at junctions and where polylines end on one another.
void refuse_side_by_side(const std::string& path, const Centerlines& c, UnionFind& same,
                         const std::vector<Segment>& unique, const Incidence& inc) {
  const std::size_t n = c.point_count();
  const std::vector<std::size_t>& first = inc.first;
  const std::vector<std::size_t>& at = inc.at;
  const auto degree = [&](std::size_t p) { return inc.degree(p); };
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
}

// Chains, found in the polylines' order and oriented as written there.
std::vector<Chain> chains_of(const std::string& path, const Centerlines& c, const std::vector<Segment>& unique,
                             const Incidence& inc) {
  const std::vector<std::size_t>& first = inc.first;
  const std::vector<std::size_t>& at = inc.at;
  const auto degree = [&](std::size_t p) { return inc.degree(p); };
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
  return chains;
}

Network build_network(const std::string& path, const Centerlines& c, const ImportOptions& options,
                      const CenterlineOptions& co) {
  check_points(path, c, co);

  UnionFind same(c.point_count());
  const std::size_t coincident = merge_coincident(c, same);

  const Segments segments = unique_segments(path, c, same);
  const std::vector<Segment>& unique = segments.unique;
  const std::size_t overlapping = segments.overlapping, repeated_points = segments.repeated_points,
                    single_point_cells = segments.single_point_cells;
  const std::size_t n = c.point_count();
  const Incidence inc = incidence(n, unique);
  refuse_side_by_side(path, c, same, unique, inc);
  const std::vector<Chain> chains = chains_of(path, c, unique, inc);

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
}  // namespace vtk

Network read_vtk_centerline(const std::string& path, const ImportOptions& options, const CenterlineOptions& centerline) {
  using namespace vtk;
  if (!(centerline.length_unit > 0) || !std::isfinite(centerline.length_unit))
    throw InputError(path + ": the length unit must be a positive number of metres (got " +
                     format_number(centerline.length_unit) + ")");
  std::string text = read_whole_file(path);
  std::size_t start = 0;
  if (text.rfind("\xEF\xBB\xBF", 0) == 0) start = 3;  // a UTF-8 byte order mark
  while (start < text.size() && is_space(text[start])) ++start;
  Centerlines c;
  if (text.compare(start, 14, "# vtk DataFile") == 0) c = read_legacy(path, text.substr(start), centerline);
  else if (text.compare(start, 1, "<") == 0) c = read_xml(path, std::move(text), centerline);
  else throw InputError(path + ": neither VTK XML (.vtp) nor a legacy VTK file ('# vtk DataFile ...')");
  return build_network(path, c, options, centerline);
}

}  // namespace hemotree
