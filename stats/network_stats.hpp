// Descriptive statistics of a network: the paper's Figure 4 per-generation statistics
// (counts by class, diameter quartiles) and whole-network totals.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <ostream>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/setting_error.hpp"
#include "formats/network.hpp"

namespace hemotree {

struct Quartiles {
  double min = 0, q1 = 0, median = 0, q3 = 0, max = 0;
};

struct GenerationStats {
  int generation = 0;
  std::size_t vessels = 0;
  std::array<std::size_t, vessel_class_count> by_class{};
  Quartiles diameter;  // [m]
};

// One connected part of the network (formats/connected_parts.hpp), named by its lowest vessel
// id: its size, its boundary nodes, and whether one of them is a pressure or an outlet (a
// pressure to refer to); if none is, whether its flow boundaries balance (net_inflow, the sum
// of their mean flows into it, within 1e-9 of the largest) as a pressure at one node needs.
struct PartStats {
  std::int64_t lowest_vessel_id = 0;
  std::size_t vessels = 0;
  std::size_t nodes = 0;
  std::size_t boundary_nodes = 0;
  bool pressure_reference = false;
  bool flows_balance = true;
  double net_inflow = 0;  // [m^3/s]
};

struct NetworkStats {
  std::size_t vessels = 0;
  std::size_t bifurcations = 0;  // nodes where one vessel ends and two or more begin (trees)
  std::size_t terminals = 0;     // vessels whose distal node starts no vessel (trees)
  // Any graph, whatever the vessels' directions: nodes by how many vessels meet there
  // (index = degree; 1: ends, 2: vessel continues, 3: bifurcations and confluences, ...),
  // connected parts, independent loops (vessels - nodes + parts, the cycle rank; 0 for a
  // tree), and boundary conditions by type (flow, pressure, RCR, R, reflection).
  std::vector<std::size_t> nodes_by_degree;
  std::size_t parts = 0;
  std::vector<PartStats> parts_by_size;  // largest first: most vessels, then lowest vessel id
  std::size_t loops = 0;
  std::array<std::size_t, 5> boundaries_by_type{};
  double total_length = 0;       // [m]
  double total_volume = 0;       // [m^3]
  std::array<std::size_t, vessel_class_count> by_class{};
  std::vector<GenerationStats> generations;  // generation 0 first, none skipped
  int capillary_generation_min = -1;         // -1 when there are no capillaries
  int capillary_generation_max = -1;
};

NetworkStats compute_stats(const Network& net);
nlohmann::json to_json(const NetworkStats& stats);
// The statistics as a table; where it points to a setting (the JSON form, for parts left out)
// it names it in words (core/setting_error.hpp: vstats's are its flags).
void print_table(const NetworkStats& stats, std::ostream& out, const SettingWords& words = {});

}  // namespace hemotree
