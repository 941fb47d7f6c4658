#include "stats/network_stats.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <span>
#include <stdexcept>
#include <string>

#include "core/errors.hpp"
#include "formats/connected_parts.hpp"

namespace hemotree {

namespace {

// Generations are array indices here (one table row each). No vessel of a consistently
// labelled network lies deeper than the vessel count - 1, and the reader refuses files that
// say otherwise (a 17-vessel file with generation 999999 printed a 110 MB table). Networks
// built in code may carry other labels: up to this many rows are allowed for them.
constexpr std::size_t min_generation_rows = 10'000;

std::string vessel_name(const Network& net, std::size_t v) {
  return "vessel " + std::to_string(net.id[v]);
}

// One pass that makes the arrays safe to index with: every later loop trusts them.
void check_network(const Network& net) {
  const std::size_t n = net.vessel_count();
  if (net.from.size() != n || net.to.size() != n || net.length.size() != n ||
      net.diameter.size() != n || net.generation.size() != n || net.vessel_class.size() != n)
    throw std::invalid_argument("compute_stats: vessel arrays of unequal length");

  const auto nodes = static_cast<std::int64_t>(net.node_count());
  const std::size_t rows = std::max(n, min_generation_rows);
  for (std::size_t v = 0; v < n; ++v) {
    if (net.from[v] < 0 || net.from[v] >= nodes || net.to[v] < 0 || net.to[v] >= nodes)
      throw InputError(vessel_name(net, v) + ": node index out of range");
    if (net.generation[v] < 0 || static_cast<std::size_t>(net.generation[v]) >= rows)
      throw InputError(vessel_name(net, v) + ": \"generation\" must lie in [0, " +
                       std::to_string(rows - 1) + "] (got " + std::to_string(net.generation[v]) +
                       ")");
    if (static_cast<int>(net.vessel_class[v]) >= vessel_class_count)
      throw InputError(vessel_name(net, v) + ": unknown vessel class");
    if (std::isnan(net.diameter[v]))  // NaN has no place in an ordering: quartiles need one
      throw InputError(vessel_name(net, v) + ": diameter is not a number");
  }
}

// Puts the values that belong at the sorted, distinct positions `ranks` (all within
// [lo, hi)) where a full sort would put them, given that v[lo, hi) already holds the values
// of those positions in some order. nth_element on the middle rank splits the range and
// each side is handled alone; a rank at either end of its range is just the range's
// minimum or maximum, found by a scan, which is cheaper than a partition.
void place_ranks(std::span<double> v, std::size_t lo, std::size_t hi,
                 std::span<const std::size_t> ranks) {
  const auto at = [&](std::size_t i) { return v.begin() + static_cast<std::ptrdiff_t>(i); };
  while (!ranks.empty()) {
    if (ranks.front() == lo) {
      std::iter_swap(at(lo), std::min_element(at(lo), at(hi)));
      ++lo;
      ranks = ranks.subspan(1);
    } else if (ranks.back() == hi - 1) {
      std::iter_swap(at(hi - 1), std::max_element(at(lo), at(hi)));
      --hi;
      ranks = ranks.first(ranks.size() - 1);
    } else {
      const std::size_t m = ranks.size() / 2;
      std::nth_element(at(lo), at(ranks[m]), at(hi));
      place_ranks(v, lo, ranks[m], ranks.first(m));
      lo = ranks[m] + 1;
      ranks = ranks.subspan(m + 1);
    }
  }
}

// Quartiles of the values in v, which it reorders.
//
// Percentile p follows numpy's default (method "linear"): with the values sorted,
// x_0 <= ... <= x_{n-1}, let h = (n-1) p, k = floor(h); then
//   P(p) = x_k + (h - k) (x_{k+1} - x_k).
// E.g. 10, 20, 30, 40 give q1 = 17.5, median = 25, q3 = 32.5.
// Only the order statistics that formula reads are put in place, so a generation costs a
// few linear passes instead of the O(n log n) of a full sort.
Quartiles quartiles(std::span<double> v) {
  const std::size_t n = v.size();
  if (n == 0) return {};

  const auto lower_rank = [&](double p) {
    return static_cast<std::size_t>(std::floor(static_cast<double>(n - 1) * p));
  };
  std::vector<std::size_t> ranks = {0, n - 1};
  for (double p : {0.25, 0.5, 0.75}) {
    ranks.push_back(lower_rank(p));
    ranks.push_back(std::min(lower_rank(p) + 1, n - 1));
  }
  std::sort(ranks.begin(), ranks.end());
  ranks.erase(std::unique(ranks.begin(), ranks.end()), ranks.end());
  place_ranks(v, 0, n, ranks);

  const auto percentile = [&](double p) {
    const std::size_t k = lower_rank(p);
    const double h = static_cast<double>(n - 1) * p;
    return v[k] + (h - static_cast<double>(k)) * (v[std::min(k + 1, n - 1)] - v[k]);
  };
  return {v[0], percentile(0.25), percentile(0.5), percentile(0.75), v[n - 1]};
}

nlohmann::json class_counts_json(const std::array<std::size_t, vessel_class_count>& counts) {
  nlohmann::json out = nlohmann::json::object();
  for (int c = 0; c < vessel_class_count; ++c)
    out[std::string(to_string(static_cast<VesselClass>(c)))] = counts[c];
  return out;
}

// printf into a std::string: the table is a few hundred short lines at most.
template <typename... Args>
std::string format(const char* pattern, Args... args) {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, pattern, args...);
  return buffer;
}

// The connected parts, largest first: all of them up to a screenful, then what the rest hold.
void print_parts(const NetworkStats& stats, std::ostream& out, const SettingWords& words) {
  constexpr std::size_t shown = 20;
  const auto& parts = stats.parts_by_size;
  if (parts.empty()) return;
  out << '\n'
      << format("%-22s %10s %10s %15s  %s\n", "connected parts", "vessels", "nodes", "boundary nodes",
                "pressure reference");
  for (std::size_t k = 0; k < std::min(parts.size(), shown); ++k) {
    const PartStats& part = parts[k];
    const std::string reference = part.pressure_reference ? "yes"
                                  : part.boundary_nodes == 0 ? "no (no boundary)"
                                  : part.flows_balance      ? "no (flows balance)"
                                                            : format("no (net inflow %.6g ml/min)", part.net_inflow * 60e6);
    out << format("%-22s %10zu %10zu %15zu  %s\n", ("  with vessel " + std::to_string(part.lowest_vessel_id)).c_str(),
                  part.vessels, part.nodes, part.boundary_nodes, reference.c_str());
  }
  if (parts.size() > shown) {
    std::size_t vessels = 0, nodes = 0, boundary_nodes = 0;
    for (std::size_t k = shown; k < parts.size(); ++k) {
      vessels += parts[k].vessels;
      nodes += parts[k].nodes;
      boundary_nodes += parts[k].boundary_nodes;
    }
    out << format("%-22s %10zu %10zu %15zu  (%s lists them all)\n",
                  ("  " + std::to_string(parts.size() - shown) + " more").c_str(), vessels, nodes, boundary_nodes,
                  in_words(placeholder("json"), words).c_str());
  }
}

}  // namespace

NetworkStats compute_stats(const Network& net) {
  check_network(net);
  NetworkStats stats;
  const std::size_t n = net.vessel_count();
  stats.vessels = n;

  // Branching: how many vessels end at and begin at each node.
  std::vector<std::uint32_t> ending(net.node_count(), 0), beginning(net.node_count(), 0);
  for (std::size_t v = 0; v < n; ++v) {
    ++beginning[static_cast<std::size_t>(net.from[v])];
    ++ending[static_cast<std::size_t>(net.to[v])];
  }
  for (std::size_t node = 0; node < net.node_count(); ++node)
    if (ending[node] >= 1 && beginning[node] >= 2) ++stats.bifurcations;

  // Degrees, parts, loops: the graph as it is, directions aside.
  std::size_t touched = 0;
  for (std::size_t node = 0; node < net.node_count(); ++node) {
    const std::size_t degree = ending[node] + beginning[node];
    if (degree == 0) continue;
    ++touched;
    if (stats.nodes_by_degree.size() <= degree) stats.nodes_by_degree.resize(degree + 1, 0);
    ++stats.nodes_by_degree[degree];
  }
  const std::vector<NodeBoundary> boundaries = node_boundaries(net);
  for (const ConnectedPart& part : connected_parts(net, boundaries).parts)
    stats.parts_by_size.push_back({part.lowest_vessel_id, part.vessels, part.nodes, part.boundary_nodes.size(),
                                   part.pressure_reference, part.flows_balance(), part.net_inflow});
  stats.parts = stats.parts_by_size.size();
  stats.loops = n + stats.parts - touched;
  for (const NodeBoundary& b : boundaries) ++stats.boundaries_by_type[static_cast<std::size_t>(b.type)];

  int max_generation = -1;
  for (std::size_t v = 0; v < n; ++v) {
    if (beginning[static_cast<std::size_t>(net.to[v])] == 0) ++stats.terminals;
    stats.total_length += net.length[v];
    stats.total_volume += net.volume(v);
    max_generation = std::max(max_generation, static_cast<int>(net.generation[v]));
  }

  // Counts per generation and class (the class as stored, so a file's own classification
  // is what is counted); every generation up to the deepest gets a row, so an unpopulated
  // one shows as zeros rather than vanishing.
  const auto generations = static_cast<std::size_t>(max_generation + 1);
  stats.generations.resize(generations);
  for (std::size_t g = 0; g < generations; ++g)
    stats.generations[g].generation = static_cast<int>(g);
  for (std::size_t v = 0; v < n; ++v) {
    auto& row = stats.generations[static_cast<std::size_t>(net.generation[v])];
    ++row.vessels;
    ++row.by_class[static_cast<std::size_t>(net.vessel_class[v])];
  }

  // Counting sort of the diameters into one bucket per generation (one pass), then the
  // quartiles of each bucket in place.
  std::vector<std::size_t> next(generations + 1, 0);
  for (std::size_t g = 0; g < generations; ++g)
    next[g + 1] = next[g] + stats.generations[g].vessels;
  std::vector<double> bucketed(n);
  for (std::size_t v = 0; v < n; ++v)
    bucketed[next[static_cast<std::size_t>(net.generation[v])]++] = net.diameter[v];
  // After the scatter next[g] is the end of bucket g, and so the start of bucket g + 1.
  std::size_t start = 0;
  for (std::size_t g = 0; g < generations; ++g) {
    auto& row = stats.generations[g];
    row.diameter = quartiles(std::span<double>(bucketed).subspan(start, row.vessels));
    start = next[g];
  }

  const auto capillary = static_cast<std::size_t>(VesselClass::capillary);
  for (const auto& row : stats.generations) {
    for (int c = 0; c < vessel_class_count; ++c) stats.by_class[c] += row.by_class[c];
    if (row.by_class[capillary] > 0) {
      if (stats.capillary_generation_min < 0) stats.capillary_generation_min = row.generation;
      stats.capillary_generation_max = row.generation;
    }
  }
  return stats;
}

nlohmann::json to_json(const NetworkStats& stats) {
  nlohmann::json out = nlohmann::json::object();
  out["vessels"] = stats.vessels;
  out["bifurcations"] = stats.bifurcations;
  out["terminals"] = stats.terminals;
  nlohmann::json degrees = nlohmann::json::object();
  for (std::size_t d = 1; d < stats.nodes_by_degree.size(); ++d)
    if (stats.nodes_by_degree[d] > 0) degrees[std::to_string(d)] = stats.nodes_by_degree[d];
  out["nodes_by_degree"] = std::move(degrees);
  out["parts"] = stats.parts;
  nlohmann::json parts = nlohmann::json::array();
  for (const PartStats& part : stats.parts_by_size)
    parts.push_back({{"lowest_vessel_id", part.lowest_vessel_id},
                     {"vessels", part.vessels},
                     {"nodes", part.nodes},
                     {"boundary_nodes", part.boundary_nodes},
                     {"pressure_reference", part.pressure_reference},
                     {"flows_balance", part.flows_balance},
                     {"net_inflow", part.net_inflow}});
  out["connected_parts"] = std::move(parts);
  out["loops"] = stats.loops;
  nlohmann::json boundaries = nlohmann::json::object();
  for (std::size_t t = 0; t < stats.boundaries_by_type.size(); ++t)
    boundaries[std::string(to_string(static_cast<BoundaryType>(t)))] = stats.boundaries_by_type[t];
  out["boundary_nodes"] = std::move(boundaries);
  out["total_length"] = stats.total_length;
  out["total_volume"] = stats.total_volume;
  out["classes"] = class_counts_json(stats.by_class);
  if (stats.capillary_generation_min < 0) {
    out["capillary_generations"] = nullptr;
  } else {
    out["capillary_generations"] = {
        {"min", stats.capillary_generation_min},
        {"max", stats.capillary_generation_max},
        {"span", stats.capillary_generation_max - stats.capillary_generation_min + 1}};
  }
  nlohmann::json generations = nlohmann::json::array();
  for (const auto& row : stats.generations) {
    const auto& d = row.diameter;
    generations.push_back({{"generation", row.generation},
                           {"vessels", row.vessels},
                           {"classes", class_counts_json(row.by_class)},
                           {"diameter",
                            {{"min", d.min},
                             {"q1", d.q1},
                             {"median", d.median},
                             {"q3", d.q3},
                             {"max", d.max}}}});
  }
  out["generations"] = std::move(generations);
  return out;
}

void print_table(const NetworkStats& stats, std::ostream& out, const SettingWords& words) {
  const double m3_per_ml = 1e-6;
  const double um_per_m = 1e6;
  const auto percent = [&](std::size_t count) {
    if (stats.vessels == 0) return 0.0;
    return 100.0 * static_cast<double>(count) / static_cast<double>(stats.vessels);
  };

  out << format("%-22s %12zu\n", "vessels", stats.vessels)
      << format("%-22s %12zu\n", "bifurcations", stats.bifurcations)
      << format("%-22s %12zu\n", "terminals", stats.terminals)
      << format("%-22s %12zu\n", "parts", stats.parts)
      << format("%-22s %12zu\n", "loops", stats.loops);
  for (std::size_t d = 1; d < stats.nodes_by_degree.size(); ++d)
    if (stats.nodes_by_degree[d] > 0)
      out << format("%-22s %12zu\n", ("nodes of degree " + std::to_string(d)).c_str(), stats.nodes_by_degree[d]);
  std::size_t boundary_nodes = 0;
  std::string by_type;
  for (std::size_t t = 0; t < stats.boundaries_by_type.size(); ++t) {
    boundary_nodes += stats.boundaries_by_type[t];
    if (stats.boundaries_by_type[t] > 0)
      by_type += (by_type.empty() ? "" : ", ") + std::to_string(stats.boundaries_by_type[t]) + " " +
                 std::string(to_string(static_cast<BoundaryType>(t)));
  }
  out << format("%-22s %12zu", "boundary nodes", boundary_nodes) << (by_type.empty() ? "" : "  (" + by_type + ")")
      << "\n"
      << format("%-22s %12.6g m\n", "total length", stats.total_length)
      << format("%-22s %12.6g m^3  (%.6g ml)\n", "total volume", stats.total_volume,
                stats.total_volume / m3_per_ml);
  for (int c = 0; c < vessel_class_count; ++c) {
    const std::string name(to_string(static_cast<VesselClass>(c)));
    out << format("%-22s %12zu  (%6.2f %%)\n", name.c_str(), stats.by_class[c],
                  percent(stats.by_class[c]));
  }
  if (stats.capillary_generation_min < 0)
    out << format("%-22s %12s\n", "capillary generations", "none");
  else
    out << format("%-22s %5d to %3d  (%d generations)\n", "capillary generations",
                  stats.capillary_generation_min, stats.capillary_generation_max,
                  stats.capillary_generation_max - stats.capillary_generation_min + 1);

  print_parts(stats, out, words);

  // Class columns in VesselClass order, abbreviated so a row fits 110 characters.
  out << '\n'
      << format("%5s %10s %9s %9s %9s %9s | %9s %9s %9s %9s %9s\n", "gen", "vessels", "artery",
                "small_art", "arteriole", "capillary", "D_min", "D_q1", "D_median", "D_q3",
                "D_max")
      << format("%5s %10s %9s %9s %9s %9s | %49s\n", "", "", "", "", "", "", "diameters in um");
  for (const auto& row : stats.generations) {
    const auto& d = row.diameter;
    out << format("%5d %10zu %9zu %9zu %9zu %9zu | %9.2f %9.2f %9.2f %9.2f %9.2f\n",
                  row.generation, row.vessels, row.by_class[0], row.by_class[1], row.by_class[2],
                  row.by_class[3], d.min * um_per_m, d.q1 * um_per_m, d.median * um_per_m,
                  d.q3 * um_per_m, d.max * um_per_m);
  }
}

}  // namespace hemotree
