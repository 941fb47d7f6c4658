#include "formats/network.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <numbers>

#include "core/errors.hpp"

namespace hemotree {

VesselClass classify(double diameter) {
  if (diameter >= artery_min_diameter) return VesselClass::artery;
  if (diameter >= small_artery_min_diameter) return VesselClass::small_artery;
  if (diameter >= arteriole_min_diameter) return VesselClass::arteriole;
  return VesselClass::capillary;
}

std::string_view to_string(VesselClass c) {
  switch (c) {
    case VesselClass::artery: return "artery";
    case VesselClass::small_artery: return "small_artery";
    case VesselClass::arteriole: return "arteriole";
    case VesselClass::capillary: return "capillary";
  }
  return "unknown";
}

std::optional<VesselClass> parse_vessel_class(std::string_view name) {
  for (int c = 0; c < vessel_class_count; ++c)
    if (to_string(static_cast<VesselClass>(c)) == name) return static_cast<VesselClass>(c);
  return std::nullopt;
}

void Network::reserve(std::size_t vessels, std::size_t nodes) {
  node_id.reserve(nodes);
  id.reserve(vessels);
  from.reserve(vessels);
  to.reserve(vessels);
  length.reserve(vessels);
  diameter.reserve(vessels);
  wall_thickness.reserve(vessels);
  youngs_modulus.reserve(vessels);
  generation.reserve(vessels);
  vessel_class.reserve(vessels);
}

void Network::shrink_to_fit() {
  // Every member by name, as network_identity: a member added to Network stops this from compiling.
  auto& [node_id_, x_, y_, z_, id_, from_, to_, length_, diameter_, wall_thickness_, youngs_modulus_, generation_,
         vessel_class_, beta_, reference_pressure_, distal_diameter_, blood_, inlet_, outlets_, boundaries_,
         provenance_, extra_] = *this;
  (void)blood_, (void)inlet_, (void)provenance_, (void)extra_;  // no arrays
  node_id_.shrink_to_fit();
  id_.shrink_to_fit();
  for (auto* v : {&x_, &y_, &z_, &length_, &diameter_, &wall_thickness_, &youngs_modulus_, &beta_,
                  &reference_pressure_, &distal_diameter_})
    v->shrink_to_fit();
  for (auto* v : {&from_, &to_, &generation_}) v->shrink_to_fit();
  vessel_class_.shrink_to_fit();
  outlets_.shrink_to_fit();
  boundaries_.shrink_to_fit();
}

std::int32_t Network::add_node(std::int64_t node_id_value) {
  node_id.push_back(node_id_value);
  return static_cast<std::int32_t>(node_id.size() - 1);
}

std::int32_t Network::add_node(std::int64_t node_id_value, double px, double py, double pz) {
  x.push_back(px);
  y.push_back(py);
  z.push_back(pz);
  return add_node(node_id_value);
}

std::size_t Network::add_vessel(std::int64_t vessel_id, std::int32_t from_node,
                                std::int32_t to_node, double length_m, double diameter_m,
                                double wall_thickness_m, double youngs_modulus_pa,
                                std::int32_t generation_index) {
  id.push_back(vessel_id);
  from.push_back(from_node);
  to.push_back(to_node);
  length.push_back(length_m);
  diameter.push_back(diameter_m);
  wall_thickness.push_back(wall_thickness_m);
  youngs_modulus.push_back(youngs_modulus_pa);
  generation.push_back(generation_index);
  vessel_class.push_back(classify(diameter_m));
  return id.size() - 1;
}

std::int64_t Network::index_of(std::int64_t vessel_id) const {
  if (vessel_id >= 0 && static_cast<std::size_t>(vessel_id) < id.size() &&
      id[static_cast<std::size_t>(vessel_id)] == vessel_id)
    return vessel_id;
  for (std::size_t v = 0; v < id.size(); ++v)
    if (id[v] == vessel_id) return static_cast<std::int64_t>(v);
  return -1;
}

void require_tube_laws(const Network& net, const std::string& source) {
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    if (!net.beta.empty() && !std::isnan(net.beta[v])) continue;
    const char* missing = std::isnan(net.wall_thickness[v])   ? "wall_thickness"
                          : std::isnan(net.youngs_modulus[v]) ? "youngs_modulus"
                                                              : nullptr;
    if (missing)
      throw InputError(source + ": vessel " + std::to_string(net.id[v]) + ": missing \"" +
                       missing + "\" (a tube law needs \"wall_thickness\" and " +
                       "\"youngs_modulus\", or \"beta\" and \"reference_pressure\")");
  }
}

double Network::volume(std::size_t v) const {
  if (!is_tapered(v)) return std::numbers::pi / 4.0 * diameter[v] * diameter[v] * length[v];
  const double d0 = diameter[v], d1 = distal_diameter[v];
  return std::numbers::pi / 12.0 * (d0 * d0 + d0 * d1 + d1 * d1) * length[v];
}

NodeBoundary as_node_boundary(const Network& net, const Outlet& outlet) {
  NodeBoundary b;
  b.node = net.to[static_cast<std::size_t>(outlet.vessel)];
  b.type = outlet.type;
  b.outlet = outlet;
  return b;
}

NodeBoundary as_node_boundary(const Network& net, const Inlet& inlet) {
  const std::int64_t v = net.index_of(inlet.vessel);
  if (v < 0) throw InputError("inlet: unknown vessel " + std::to_string(inlet.vessel));
  NodeBoundary b;
  b.node = net.from[static_cast<std::size_t>(v)];
  b.type = BoundaryType::flow;
  b.waveform = inlet.waveform;
  return b;
}

// One byte per node rather than a sort of the conditions.
void check_one_boundary_per_node(const Network& net) {
  constexpr unsigned char none = 0xff;
  std::vector<unsigned char> type_at(net.node_count(), none);
  std::int64_t worst = -1;
  BoundaryType first{}, second{};
  auto add = [&](std::int64_t node, BoundaryType type) {
    unsigned char& seen = type_at[static_cast<std::size_t>(node)];
    if (seen == none) {
      seen = static_cast<unsigned char>(type);
    } else if (worst < 0 || node < worst) {
      worst = node, first = static_cast<BoundaryType>(seen), second = type;
    }
  };
  for (const NodeBoundary& b : net.boundaries) add(b.node, b.type);
  if (net.inlet) add(as_node_boundary(net, *net.inlet).node, BoundaryType::flow);
  for (const Outlet& o : net.outlets) add(net.to[static_cast<std::size_t>(o.vessel)], o.type);
  if (worst >= 0)
    throw InputError("node " + std::to_string(net.node_id[static_cast<std::size_t>(worst)]) +
                     " has two boundary conditions (" + std::string(to_string(first)) + " and " +
                     std::string(to_string(second)) + "): one per node");
}

std::vector<NodeBoundary> node_boundaries(const Network& net) {
  check_one_boundary_per_node(net);
  std::vector<NodeBoundary> all = net.boundaries;
  if (net.inlet) all.push_back(as_node_boundary(net, *net.inlet));
  for (const Outlet& o : net.outlets) all.push_back(as_node_boundary(net, o));
  // By node: the nodes are distinct, so sorting (node, place) pairs is stable, and moves
  // 16 bytes a condition rather than the condition.
  std::vector<std::pair<std::int64_t, std::size_t>> key(all.size());
  for (std::size_t k = 0; k < all.size(); ++k) key[k] = {all[k].node, k};
  if (!std::is_sorted(key.begin(), key.end())) {
    std::sort(key.begin(), key.end());
    std::vector<NodeBoundary> sorted;
    sorted.reserve(all.size());
    for (const auto& [node, k] : key) sorted.push_back(std::move(all[k]));
    all = std::move(sorted);
  }
  return all;
}

Waveform driving_waveform(const Network& net) {
  check_one_boundary_per_node(net);
  // The run's conditions that are not outlets, in its order (formats/run_boundaries.hpp).
  std::vector<NodeBoundary> list;
  if (net.inlet) list.push_back(as_node_boundary(net, *net.inlet));
  list.insert(list.end(), net.boundaries.begin(), net.boundaries.end());
  const NodeBoundary* first = nullptr;
  for (const NodeBoundary& b : list) {
    if (b.is_outlet() || b.waveform.shape == Waveform::Shape::constant) continue;
    if (!first) {
      first = &b;
    } else if (std::abs(b.waveform.period - first->waveform.period) > 1e-9 * first->waveform.period) {
      auto name = [&](const NodeBoundary& x) { return "node " + std::to_string(net.node_id[static_cast<std::size_t>(x.node)]); };
      throw InputError("the boundary waveforms at " + name(*first) + " and " + name(b) + " have different periods (" +
                       std::to_string(first->waveform.period) + " s and " + std::to_string(b.waveform.period) +
                       " s): a pulsatile run needs one period for all");
    }
  }
  if (first) return first->waveform;
  if (net.inlet) return net.inlet->waveform;
  return Waveform::constant_value(0.0);  // period 1 s
}

void sort_boundaries_by_node(Network& net) {
  std::stable_sort(net.boundaries.begin(), net.boundaries.end(),
                   [](const NodeBoundary& p, const NodeBoundary& q) { return p.node < q.node; });
  node_boundaries(net);
}

}  // namespace hemotree
