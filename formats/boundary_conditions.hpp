// What a network carries for flow computations: blood properties, the inflow at its inlet
// and the 0D models that stand for the vasculature beyond its outlets. SI units.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace hemotree {

enum class Rheology { pries, newtonian };

struct Blood {
  double density = 1050.0;            // [kg/m^3]
  double plasma_viscosity = 1.0e-3;   // [Pa s], water (the paper's nu = 1e-6 m^2/s)
  double hematocrit = 0.45;           // discharge hematocrit H_d
  double alpha = 4.0 / 3.0;           // velocity-profile (Coriolis) coefficient; 4/3 parabolic
  Rheology rheology = Rheology::pries;
  double newtonian_viscosity = 3.4e-3;   // [Pa s], the paper's constant-viscosity runs
  double pries_max_diameter = 300e-6;    // [m]; above it the viscosity stays at its value there
};

// Periodic inflow Q(t) [m^3/s].
struct Waveform {
  enum class Shape { half_sine, table } shape = Shape::half_sine;
  double period = 1.0;     // [s]
  // half_sine: Q = Q_max sin(pi t / systole) during systole, 0 in diastole; Q_max from mean
  double mean = 0.0;       // [m^3/s]
  double systole = 0.3;    // [s]
  // table: (time, flow) samples over one period, linearly interpolated, wrapped periodically
  std::vector<double> time, flow;

  double operator()(double t) const;
  double peak() const;
  double mean_flow() const;  // over one period
};

struct Inlet {
  std::int64_t vessel = 0;  // vessel id (not index): the flow enters at its `from` node
  Waveform waveform;
};

enum class OutletType { rcr, resistance, reflection };

// The 0D model at the distal node of a terminal vessel.
struct Outlet {
  std::int32_t vessel = -1;   // vessel index
  OutletType type = OutletType::resistance;
  double r1 = 0, c = 0, r2 = 0;   // RCR: [Pa s/m^3], [m^3/Pa], [Pa s/m^3]
  double r = 0;                   // R: [Pa s/m^3]
  double p_out = 0;               // pressure beyond the outlet (venous) [Pa]
  double reflection = 0;          // reflection: coefficient in [-1, 1], 0 non-reflecting

  double resistance() const { return type == OutletType::rcr ? r1 + r2 : r; }
};

std::string_view to_string(OutletType type);
std::string_view to_string(Rheology rheology);

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

}  // namespace hemotree
