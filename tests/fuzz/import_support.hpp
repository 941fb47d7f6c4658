// What the importer harnesses (fuzz_import_*.cpp) share: a reader's outcome where only its
// refusal (InputError) is allowed, the network compared field by field, and the round trip
// through the vnet format that vimport makes of every accepted file.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <omp.h>

#include "exchange/foreign_format.hpp"
#include "formats/network_io.hpp"
#include "formats/output_stream.hpp"
#include "fuzz_support.hpp"

namespace hemotree::fuzz {

inline void init_import_harness() {
  keep_report_channel();
  omp_set_num_threads(1);  // one core is the fuzzer's share
}

// Runs a reader (or a writer): its value, or nullopt when it refused with InputError (and
// IoError where allow_io: the openBF inlet file a model names may be missing or a device).
// Anything else is a finding: another exception reaches vimport's user as an internal error.
template <class F>
auto refused_or(const std::string& stage, F f, bool allow_io = false) -> std::optional<decltype(f())> {
  try {
    return f();
  } catch (const InputError&) {
    return std::nullopt;
  } catch (const IoError& e) {
    if (allow_io) return std::nullopt;
    finding(stage + ": IoError on a readable file: " + e.what());
  } catch (const std::exception& e) {
    finding(stage + ": an exception that is not InputError (internal error, exit 70): " + e.what());
  } catch (...) {
    finding(stage + ": a non-standard exception");
  }
}

// Runs what must succeed: any exception at all is a finding.
template <class F>
auto must(const std::string& stage, F f) -> decltype(f()) {
  try {
    return f();
  } catch (const std::exception& e) {
    finding(stage + ": " + e.what());
  } catch (...) {
    finding(stage + ": a non-standard exception");
  }
}

inline ImportOptions quiet_options() {
  ImportOptions options;
  options.note = [](const std::string&) {};
  return options;
}

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

// vimport's last steps (exchange/vimport.cpp): provenance strings that do not serialize (a
// file name, a title that is not UTF-8) get '?' for their bytes outside ASCII.
inline void ascii_strings(nlohmann::json& j) {
  if (j.is_string()) {
    std::string s = j.get<std::string>();
    for (char& c : s)
      if (static_cast<unsigned char>(c) >= 0x80) c = '?';
    j = s;
  } else if (j.is_structured()) {
    for (auto& item : j) ascii_strings(item);
  }
}

inline void as_vimport_writes(Network& net, const std::string& format, const std::string& source) {
  if (!net.provenance.is_object()) net.provenance = nlohmann::json::object();
  net.provenance["tool"] = "vimport";
  net.provenance["format"] = format;
  net.provenance["source"] = source;
  try {
    (void)net.provenance.dump();
  } catch (const nlohmann::json::exception&) {
    ascii_strings(net.provenance);
  }
}

// What vimport writes of an accepted network: write_network must take it, the vnet reader
// must accept the file and read the same network back (reals to the writer's 9 digits).
inline void check_vnet_round_trip(Network net, const std::string& format) {
  as_vimport_writes(net, format, "fuzz-input");
  const auto path = scratch() / "imported.json";
  must("write_network refused what the " + format + " reader accepted", [&] {
    OutputStream out(path.string());
    write_network(net, out);
    out.commit();
    return true;
  });
  const std::string text = read_file(path);
  const Network back = must("the vnet reader refuses what vimport " + format + " wrote",
                            [&] { return parse_network(text, "imported.json"); });
  if (const std::string d = vnet_difference(net, back, 1e-8); !d.empty())
    finding("vimport " + format + ": written as vnet and read back, the network changed: " + d);
}

}  // namespace hemotree::fuzz
