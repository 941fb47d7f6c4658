// The 0D vessels' checkpoint (pulse/lumped_vessels.hpp): their state in the network's order,
// whatever the arrays' (a run's of one process), and a rank's share of it in the whole run's
// order (a run over ranks: pulse/lumped_order.hpp's lumped_places).
#include <algorithm>
#include <span>
#include <stdexcept>

#include "pulse/lumped_order.hpp"
#include "pulse/lumped_vessels.hpp"

namespace hemotree {

namespace {
constexpr const char* section_name = "0D vessels";
}  // namespace

std::vector<std::int32_t> LumpedVessels::network_order_edges() const {
  std::vector<std::int32_t> place;
  place.reserve(a_.size());
  for (const std::int32_t i : index_of_vessel_)
    if (i >= 0)
      for (std::size_t e = first_edge(static_cast<std::size_t>(i)); e < first_edge(static_cast<std::size_t>(i) + 1); ++e)
        place.push_back(static_cast<std::int32_t>(e));
  for (std::size_t e = vessel_edges_; e < a_.size(); ++e) place.push_back(static_cast<std::int32_t>(e));  // R1 edges
  return place;
}

std::vector<std::int32_t> LumpedVessels::network_order_nodes() const {
  std::vector<std::int32_t> edges = network_order_edges();
  edges.resize(vessel_edges_);  // the vessels' ends and inner nodes, not the R1 edges'
  std::vector<std::int32_t> place = nodes_by_first_appearance(edges, a_, b_, nodes_);
  for (std::size_t k = network_nodes_; k < nodes_; ++k)
    if (is_capacitor(k)) place.push_back(static_cast<std::int32_t>(k));
  return place;
}

void LumpedVessels::save(CheckpointWriter& out) const {
  // In the network's order (network_order_nodes): the file does not depend on the arrays'.
  out.section(section_name);
  const std::vector<std::int32_t> nodes = network_order_nodes(), edges = network_order_edges();
  auto put = [&](const std::vector<double>& values, const std::vector<std::int32_t>& place) {
    out.begin_vector(values.size());
    std::vector<double> part(block);
    for (std::size_t i = 0; i < place.size(); i += block) {
      const std::size_t n = std::min(block, place.size() - i);
      for (std::size_t j = 0; j < n; ++j) part[j] = values[static_cast<std::size_t>(place[i + j])];
      out.put_part(std::span<const double>(part).first(n));
    }
  };
  for (const auto* v : {&volume_, &previous_volume_, &pressure_, &previous_pressure_}) put(*v, nodes);
  for (const auto* v : {&flow_, &previous_flow_}) put(*v, edges);
}

void LumpedVessels::restore(CheckpointReader& in) {
  in.section(section_name);
  const std::vector<std::int32_t> nodes = network_order_nodes(), edges = network_order_edges();
  auto get = [&](std::vector<double>& values, const std::vector<std::int32_t>& place) {
    if (in.begin_vector() != values.size()) in.fail("0D vessels of another network or model");
    std::vector<double> part(block);  // read in parts, as save() writes them
    for (std::size_t i = 0; i < place.size(); i += block) {
      const std::size_t n = std::min(block, place.size() - i);
      in.get_part(std::span<double>(part).first(n));
      for (std::size_t j = 0; j < n; ++j) values[static_cast<std::size_t>(place[i + j])] = part[j];
    }
  };
  for (auto* v : {&volume_, &previous_volume_, &pressure_, &previous_pressure_}) get(*v, nodes);
  for (auto* v : {&flow_, &previous_flow_}) get(*v, edges);
  hold_coupling_pressures();
  // The resistances are functions of the pressures: the same bits as the run had.
  update_resistances();
  update_dynamic_pressures();
}

LumpedVessels::StateShare LumpedVessels::state_share(const LumpedPlaces& places) const {
  StateShare share{.node_place = {}, .edge_place = {}, .whole_nodes = places.nodes, .whole_edges = places.edges};
  const std::vector<std::int32_t> node_place = local_node_places(places), edge_place = local_edge_places(places);
  for (std::size_t k = 0; k < nodes_; ++k)
    if (!is_ghost_node(k)) share.node_place.push_back(node_place[k]);  // a ghost's is its rank's
  for (std::size_t e = 0; e < a_.size(); ++e)
    if (!is_ghost_edge(e)) share.edge_place.push_back(edge_place[e]);
  return share;
}

std::vector<double> LumpedVessels::share_values(std::size_t array) const {
  const std::vector<double>* arrays[state_arrays] = {&volume_, &previous_volume_, &pressure_, &previous_pressure_, &flow_, &previous_flow_};
  const std::vector<double>& from = *arrays[array];
  std::vector<double> values;
  if (StateShare::per_node(array)) {
    for (std::size_t k = 0; k < nodes_; ++k)
      if (!is_ghost_node(k)) values.push_back(from[k]);
  } else {
    for (std::size_t e = 0; e < a_.size(); ++e)
      if (!is_ghost_edge(e)) values.push_back(from[e]);
  }
  return values;
}

void LumpedVessels::begin_whole(CheckpointWriter& out) { out.section(section_name); }

void LumpedVessels::restore_share(CheckpointReader& in, const LumpedPlaces& places) {
  in.section(section_name);
  // Each node's and edge's value from its place, the arrays read in parts (none held whole):
  // (place, index here) in the places' order, met as the parts come.
  auto by_place = [](const std::vector<std::int32_t>& place) {
    std::vector<std::pair<std::int32_t, std::int32_t>> order(place.size());
    for (std::size_t i = 0; i < place.size(); ++i) {
      if (place[i] < 0) throw std::logic_error("LumpedVessels: a node or edge with no place in the whole run's order");
      order[i] = {place[i], static_cast<std::int32_t>(i)};
    }
    std::ranges::sort(order);
    return order;
  };
  const auto nodes = by_place(local_node_places(places)), edges = by_place(local_edge_places(places));
  auto get = [&](std::vector<double>& values, const std::vector<std::pair<std::int32_t, std::int32_t>>& order, std::size_t whole) {
    if (in.begin_vector() != whole) in.fail("0D vessels of another network or model");
    std::vector<double> part(block);
    auto next = order.begin();
    for (std::size_t i = 0; i < whole; i += block) {
      const std::size_t n = std::min(block, whole - i);
      in.get_part(std::span<double>(part).first(n));
      for (; next != order.end() && static_cast<std::size_t>(next->first) < i + n; ++next)
        values[static_cast<std::size_t>(next->second)] = part[static_cast<std::size_t>(next->first) - i];
    }
    if (next != order.end()) in.fail("0D vessels of another network or model");
  };
  for (auto* v : {&volume_, &previous_volume_, &pressure_, &previous_pressure_}) get(*v, nodes, places.nodes);
  for (auto* v : {&flow_, &previous_flow_}) get(*v, edges, places.edges);
  // A ghost's volume is its own rank's, whose node sums more vessels: here the node's excess
  // at its pressure, as a step leaves it (its sums are its rank's).
  for (std::size_t k = 0; k < nodes_; ++k)
    if (is_ghost_node(k)) {
      volume_[k] = node_excess(k, pressure_[k]);
      previous_volume_[k] = node_excess(k, previous_pressure_[k]);
    }
  hold_coupling_pressures();
  update_resistances();
  update_dynamic_pressures();
}

std::vector<std::int32_t> LumpedVessels::local_node_places(const LumpedPlaces& places) const {
  if (sectioned()) throw std::logic_error("LumpedVessels: a share's checkpoint with vessels in sections");
  std::vector<std::int32_t> place(nodes_, -1);
  for (std::size_t n = 0; n < node_of_.size(); ++n)
    if (const std::int32_t k = node_of_[n]; k >= 0) place[static_cast<std::size_t>(k)] = places.node[n];
  for (std::size_t j = 0; j < outlet_of_capacitor_.size(); ++j)
    place[network_nodes_ + j] = places.capacitor[static_cast<std::size_t>(outlet_of_capacitor_[j])];
  return place;
}

std::vector<std::int32_t> LumpedVessels::local_edge_places(const LumpedPlaces& places) const {
  std::vector<std::int32_t> place(a_.size(), -1);
  for (std::size_t i = 0; i < vessels_.size(); ++i) place[i] = places.vessel[static_cast<std::size_t>(vessels_[i])];
  for (std::size_t j = 0; j < outlet_of_capacitor_.size(); ++j)
    place[vessel_edges_ + j] = places.r1_edge[static_cast<std::size_t>(outlet_of_capacitor_[j])];
  return place;
}

}  // namespace hemotree
