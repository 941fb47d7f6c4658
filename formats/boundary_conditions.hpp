// What a network carries for flow computations besides its blood (physics/blood.hpp, whose
// JSON form is here): the inflow at its inlet and the 0D models that stand for the
// vasculature beyond its outlets (the tree's form, format version 1), and boundary
// conditions at any node (version 2). SI units.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <string_view>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "physics/blood.hpp"

namespace hemotree {

// A periodic boundary value f(t): a volume flow [m^3/s] or a pressure [Pa].
struct Waveform {
  enum class Shape { half_sine, table, constant } shape = Shape::half_sine;
  double period = 1.0;     // [s]
  // half_sine (flows): f = f_max sin(pi t / systole) during systole, 0 in diastole, f_max
  // from the mean; constant: f = mean
  double mean = 0.0;
  double systole = 0.3;    // [s]
  // table: (time, value) samples over one period, linearly interpolated, wrapped periodically
  std::vector<double> time, value;

  static Waveform constant_value(double v) {
    Waveform w;
    w.shape = Shape::constant;
    w.mean = v;
    return w;
  }
  double operator()(double t) const;
  double peak() const;
  double mean_value() const;  // over one period
};

struct Inlet {
  std::int64_t vessel = 0;  // vessel id (not index): the flow enters at its `from` node
  Waveform waveform;
};

// The kind of a boundary condition: a prescribed flow into the network (negative: out of
// it), a prescribed pressure, or one of the 0D outlet models (rcr, resistance, reflection)
// to an outflow pressure. One enum for both file forms: an Outlet's type is one of the last
// three.
enum class BoundaryType { flow, pressure, rcr, resistance, reflection };

inline bool is_outlet_model(BoundaryType type) {
  return type == BoundaryType::rcr || type == BoundaryType::resistance || type == BoundaryType::reflection;
}

// The 0D model at the distal node of a terminal vessel.
struct Outlet {
  std::int32_t vessel = -1;   // vessel index
  BoundaryType type = BoundaryType::resistance;
  double r1 = 0, c = 0, r2 = 0;   // RCR: [Pa s/m^3], [m^3/Pa], [Pa s/m^3]
  double r = 0;                   // R: [Pa s/m^3]
  double p_out = 0;               // pressure beyond the outlet (venous) [Pa]
  double reflection = 0;          // reflection: coefficient in [-1, 1], 0 non-reflecting

  double resistance() const { return type == BoundaryType::rcr ? r1 + r2 : r; }
};

// A boundary condition at a node (format version 2): a prescribed flow into the network
// (negative: out of it), a prescribed pressure, or a 0D outlet model to its outflow
// pressure. Vessels may meet at the node in any number and orientation.

struct NodeBoundary {
  std::int32_t node = -1;  // node index
  BoundaryType type = BoundaryType::flow;
  Waveform waveform;       // flow [m^3/s] or pressure [Pa]
  Outlet outlet;           // rcr, resistance, reflection: its parameters (its vessel unused)
  // The discharge hematocrit of the blood entering here, NaN: the blood's.
  double hematocrit = std::numeric_limits<double>::quiet_NaN();

  bool is_outlet() const { return is_outlet_model(type); }
  // The discharge hematocrit blood enters with here (the blood's where none is given); NaN
  // at an outlet, whose backflow returns what it took.
  double entering_hematocrit(const Blood& blood) const {
    if (is_outlet()) return std::numeric_limits<double>::quiet_NaN();
    return hematocrit == hematocrit ? hematocrit : blood.hematocrit;
  }
};

std::string_view to_string(BoundaryType type);

// The JSON forms of docs/network-format.md; the readers throw InputError naming the field.
nlohmann::json to_json(const Blood& blood);
nlohmann::json to_json(const Inlet& inlet);
nlohmann::json to_json(const Outlet& outlet);  // without the vessel: it sits in the vessel
Blood blood_from_json(const nlohmann::json& j);
Inlet inlet_from_json(const nlohmann::json& j);
Outlet outlet_from_json(const nlohmann::json& j, const std::string& where);
// Throws InputError (prefixed with where) unless the waveform lies in the accepted ranges
// (formats/field_ranges.hpp); inlet_from_json calls it, tools that build one may too.
void check_waveform(const Waveform& wave, const std::string& where);
// A boundary's JSON form: {"node": ID, "type": ..., ...}; the node is written as the id
// given and read into NodeBoundary::node as that id (the reader resolves it to an index).
nlohmann::json to_json(const NodeBoundary& boundary, std::int64_t node_id);
NodeBoundary boundary_from_json(const nlohmann::json& j, const std::string& where, std::int64_t& node_id);

}  // namespace hemotree
