// Two networks compared field by field for the fuzz harnesses (the network reader's and the
// importers'): "" when they agree, else the first difference, named.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "formats/network_io.hpp"

namespace hemotree::fuzz {

// Same double: NaN as NaN, else within rel of the larger magnitude plus abs.
inline bool close_enough(double a, double b, double rel, double abs = 0) {
  if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b);
  if (a == b) return true;
  return std::abs(a - b) <= rel * std::max(std::abs(a), std::abs(b)) + abs;
}

// "" when equal, else the first difference, named.
inline std::string reals(const char* name, const std::vector<double>& u, const std::vector<double>& v, double rel,
                         double abs = 0) {
  if (u.size() != v.size())
    return std::string(name) + ": " + std::to_string(u.size()) + " values against " + std::to_string(v.size());
  for (std::size_t i = 0; i < u.size(); ++i)
    if (!close_enough(u[i], v[i], rel, abs)) {
      char text[96];
      std::snprintf(text, sizeof text, "[%zu]: %.17g against %.17g", i, u[i], v[i]);
      return std::string(name) + text;
    }
  return "";
}

template <class T>
std::string same(const char* name, const T& u, const T& v) {
  return u == v ? "" : std::string(name) + " differ";
}

// Every field of two networks; reals within rel (the vnet writer's 9 digits: 1e-8), the JSON
// members (blood, inlet, outlets, boundaries, provenance) exactly, as nlohmann keeps doubles.
inline std::string vnet_difference(const Network& a, const Network& b, double rel) {
  for (const std::string& d :
       {same("node ids", a.node_id, b.node_id), reals("x", a.x, b.x, rel), reals("y", a.y, b.y, rel),
        reals("z", a.z, b.z, rel), same("vessel ids", a.id, b.id), same("from", a.from, b.from),
        same("to", a.to, b.to), reals("length", a.length, b.length, rel),
        reals("diameter", a.diameter, b.diameter, rel),
        reals("wall_thickness", a.wall_thickness, b.wall_thickness, rel),
        reals("youngs_modulus", a.youngs_modulus, b.youngs_modulus, rel),
        same("generation", a.generation, b.generation), same("class", a.vessel_class, b.vessel_class),
        reals("beta", a.beta, b.beta, rel), reals("reference_pressure", a.reference_pressure, b.reference_pressure, rel),
        reals("distal_diameter", a.distal_diameter, b.distal_diameter, rel),
        same("provenance", a.provenance, b.provenance), same("extra members", a.extra, b.extra)})
    if (!d.empty()) return d;
  if (a.blood.has_value() != b.blood.has_value()) return "blood present in one only";
  if (a.blood && to_json(*a.blood) != to_json(*b.blood)) return "blood differs";
  if (a.inlet.has_value() != b.inlet.has_value()) return "inlet present in one only";
  if (a.inlet && (to_json(*a.inlet) != to_json(*b.inlet) || a.inlet->vessel != b.inlet->vessel))
    return "inlet differs";
  if (a.outlets.size() != b.outlets.size()) return "outlet counts differ";
  for (std::size_t k = 0; k < a.outlets.size(); ++k)
    if (a.outlets[k].vessel != b.outlets[k].vessel || to_json(a.outlets[k]) != to_json(b.outlets[k]))
      return "outlet " + std::to_string(k) + " differs";
  if (a.boundaries.size() != b.boundaries.size()) return "boundary counts differ";
  for (std::size_t k = 0; k < a.boundaries.size(); ++k) {
    const NodeBoundary &p = a.boundaries[k], &q = b.boundaries[k];
    if (p.node != q.node || p.node < 0 || static_cast<std::size_t>(p.node) >= a.node_count() ||
        to_json(p, a.node_id[static_cast<std::size_t>(p.node)]) != to_json(q, b.node_id[static_cast<std::size_t>(q.node)]))
      return "boundary " + std::to_string(k) + " differs";
  }
  return "";
}

}  // namespace hemotree::fuzz
