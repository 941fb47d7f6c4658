#include "formats/boundary_conditions.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <optional>
#include <string>

#include "core/errors.hpp"
#include "formats/field_ranges.hpp"

namespace hemotree {

std::string_view to_string(BoundaryType type) {
  switch (type) {
    case BoundaryType::flow: return "flow";
    case BoundaryType::pressure: return "pressure";
    case BoundaryType::rcr: return "RCR";
    case BoundaryType::resistance: return "R";
    case BoundaryType::reflection: return "reflection";
  }
  return "";
}

// ---- the inflow waveform --------------------------------------------------------------

double Waveform::peak() const {
  if (shape == Shape::constant) return mean;
  if (shape == Shape::half_sine) return mean * std::numbers::pi * period / (2 * systole);
  return *std::max_element(value.begin(), value.end());
}

double Waveform::operator()(double t) const {
  if (shape == Shape::constant) return mean;
  double phase = std::fmod(t, period);
  if (phase < 0) phase += period;
  if (shape == Shape::half_sine)
    return phase < systole ? peak() * std::sin(std::numbers::pi * phase / systole) : 0.0;
  // Linear interpolation, wrapping from the last sample to the first over one period.
  const auto k = static_cast<std::size_t>(std::upper_bound(time.begin(), time.end(), phase) - time.begin());
  const std::size_t n = time.size();
  const double t0 = k == 0 ? time[n - 1] - period : time[k - 1];
  const double q0 = k == 0 ? value[n - 1] : value[k - 1];
  const double t1 = k == n ? time[0] + period : time[k];
  const double q1 = k == n ? value[0] : value[k];
  return q0 + (q1 - q0) * (phase - t0) / (t1 - t0);
}

double Waveform::mean_value() const {
  if (shape != Shape::table) return mean;
  // Trapezoids over one period, with the wrap-around segment.
  const std::size_t n = time.size();
  double integral = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double t1 = k + 1 < n ? time[k + 1] : time[0] + period;
    const double q1 = k + 1 < n ? value[k + 1] : value[0];
    integral += 0.5 * (value[k] + q1) * (t1 - time[k]);
  }
  return integral / period;
}

// ---- JSON ----------------------------------------------------------------------------
// Every access checks the type first: a value of the wrong type is the user's mistake and
// gets one line naming the field, never a nlohmann::json exception.

namespace {

double number(const nlohmann::json& j, const char* key, const std::string& where) {
  if (!j.is_object() || !j.contains(key)) throw InputError(where + ": missing \"" + key + "\"");
  const auto& v = j.at(key);
  if (!v.is_number()) throw InputError(where + ": \"" + key + "\" must be a number");
  return v.get<double>();
}

double in_range(const nlohmann::json& j, const char* key, const FieldRange& range,
                const std::string& where) {
  const double v = number(j, key, where);
  if (!range.contains(v)) throw InputError(where + ": " + out_of_range(key, range, v));
  return v;
}

double in_range_or(const nlohmann::json& j, const char* key, const FieldRange& range,
                   double fallback, const std::string& where) {
  return j.contains(key) ? in_range(j, key, range, where) : fallback;
}

// The member as a string, or fallback when it is absent; `choices` names the allowed values.
std::string text(const nlohmann::json& j, const char* key, const std::string& fallback,
                 const std::string& where, const char* choices) {
  if (!j.contains(key)) return fallback;
  const auto& v = j.at(key);
  if (!v.is_string())
    throw InputError(where + ": \"" + key + "\" must be a string: " + choices + " (got " +
                     std::string(v.type_name()) + ")");
  return v.get<std::string>();
}

std::vector<double> samples(const nlohmann::json& w, const char* key, const std::string& where,
                            const char* values) {
  const std::string message =
      where + ": a table needs number lists \"time\" and \"" + values + "\"";
  if (!w.contains(key) || !w.at(key).is_array()) throw InputError(message);
  std::vector<double> list;
  list.reserve(w.at(key).size());
  for (const auto& v : w.at(key)) {
    if (!v.is_number()) throw InputError(message);
    list.push_back(v.get<double>());
  }
  return list;
}

std::string element(const char* key, std::size_t k) {
  return std::string(key) + "[" + std::to_string(k) + "]";
}

// A waveform's shape and samples; `values` names a table's samples ("flow" or "pressure").
// Ranges are the caller's: an inlet's flow and a node's pressure accept different values.
Waveform waveform_from_json(const nlohmann::json& w, const std::string& where, const char* values) {
  if (!w.is_object()) throw InputError(where + ": must be an object");
  Waveform wave;
  wave.period = number(w, "period", where);
  const bool flows = std::string_view(values) == "flow";
  const std::string shape = text(w, "shape", "", where, flows ? "\"half_sine\" or \"table\"" : "\"table\"");
  if (shape == "half_sine" && flows) {
    wave.shape = Waveform::Shape::half_sine;
    wave.systole = number(w, "systole", where);
    wave.mean = number(w, "mean", where);
  } else if (shape == "table") {
    wave.shape = Waveform::Shape::table;
    wave.time = samples(w, "time", where, values);
    wave.value = samples(w, values, where, values);
  } else {
    throw InputError(where + ": \"shape\" must be " + (flows ? "\"half_sine\" or \"table\"" : "\"table\""));
  }
  return wave;
}

nlohmann::json to_json(const Waveform& w, const char* values) {
  if (w.shape == Waveform::Shape::half_sine)
    return {{"shape", "half_sine"}, {"period", w.period}, {"systole", w.systole}, {"mean", w.mean}};
  return {{"shape", "table"}, {"period", w.period}, {"time", w.time}, {values, w.value}};
}

}  // namespace

nlohmann::json to_json(const Blood& b) {
  nlohmann::json j = {{"density", b.density},
                      {"plasma_viscosity", b.plasma_viscosity},
                      {"hematocrit", b.hematocrit},
                      {"alpha", b.alpha},
                      {"rheology", to_string(b.rheology)},
                      {"newtonian_viscosity", b.newtonian_viscosity},
                      {"pries_max_diameter", b.pries_max_diameter},
                      {"mean_cell_volume", b.mean_cell_volume}};
  if (!std::isnan(b.momentum_flux_coefficient)) j["momentum_flux_coefficient"] = b.momentum_flux_coefficient;
  return j;
}

Blood blood_from_json(const nlohmann::json& j) {
  const std::string where = "blood";
  if (!j.is_object()) throw InputError("\"blood\" must be an object");
  Blood b;
  b.density = in_range_or(j, "density", ranges::density, b.density, where);
  b.plasma_viscosity =
      in_range_or(j, "plasma_viscosity", ranges::viscosity, b.plasma_viscosity, where);
  b.hematocrit = in_range_or(j, "hematocrit", ranges::hematocrit, b.hematocrit, where);
  b.alpha = in_range_or(j, "alpha", ranges::alpha, b.alpha, where);
  b.momentum_flux_coefficient = in_range_or(j, "momentum_flux_coefficient", ranges::momentum_flux_coefficient,
                                            b.momentum_flux_coefficient, where);
  const std::string rheology =
      text(j, "rheology", "pries", where, "\"pries\" or \"newtonian\"");
  const std::optional<Rheology> law = rheology_of(rheology);
  if (!law) throw InputError("blood: \"rheology\" must be \"pries\" or \"newtonian\"");
  b.rheology = *law;
  b.newtonian_viscosity =
      in_range_or(j, "newtonian_viscosity", ranges::viscosity, b.newtonian_viscosity, where);
  b.pries_max_diameter = in_range_or(j, "pries_max_diameter", ranges::pries_max_diameter,
                                     b.pries_max_diameter, where);
  b.mean_cell_volume =
      in_range_or(j, "mean_cell_volume", ranges::mean_cell_volume, b.mean_cell_volume, where);
  return b;
}

nlohmann::json to_json(const Inlet& inlet) {
  return {{"vessel", inlet.vessel}, {"type", "flow"}, {"waveform", to_json(inlet.waveform, "flow")}};
}

namespace {

// A waveform's period, shape and samples in their ranges: `values` names the samples
// ("flow", "pressure"), `sample` their range and `mean` that of their mean over a period.
void check_waveform(const Waveform& wave, const std::string& where, const char* values,
                    const FieldRange& sample, const FieldRange& mean) {
  if (wave.shape == Waveform::Shape::constant) {
    if (!sample.contains(wave.mean)) throw InputError(where + ": " + out_of_range(values, sample, wave.mean));
    return;
  }
  if (!ranges::period.contains(wave.period))
    throw InputError(where + ": " + out_of_range("period", ranges::period, wave.period));
  if (wave.shape == Waveform::Shape::half_sine) {
    if (!ranges::systole.contains(wave.systole))
      throw InputError(where + ": " + out_of_range("systole", ranges::systole, wave.systole));
    if (wave.systole > wave.period)
      throw InputError(where + ": \"systole\" (" + format_number(wave.systole) +
                       " s) exceeds the period (" + format_number(wave.period) + " s)");
    if (!mean.contains(wave.mean)) throw InputError(where + ": " + out_of_range("mean", mean, wave.mean));
    return;
  }
  if (wave.time.size() < 2 || wave.time.size() != wave.value.size())
    throw InputError(where + ": \"time\" and \"" + values + "\" need the same length, at least 2");
  for (std::size_t k = 0; k < wave.value.size(); ++k)
    if (!sample.contains(wave.value[k]))
      throw InputError(where + ": " + out_of_range(element(values, k), sample, wave.value[k]));
  for (std::size_t k = 1; k < wave.time.size(); ++k)
    if (!(wave.time[k] > wave.time[k - 1]))
      throw InputError(where + ": times must increase (" + element("time", k) + " = " +
                       format_number(wave.time[k]) + " s)");
  if (wave.time.front() < 0 || !(wave.time.back() < wave.period + wave.time.front()))
    throw InputError(where + ": times must lie within one period, from \"time\"[0] >= 0");
  const double m = wave.mean_value();
  if (!mean.contains(m))
    throw InputError(where + ": the table's mean " + values + " must lie in " + describe(mean) +
                     " (got " + format_number(m) + ")");
}

}  // namespace

void check_waveform(const Waveform& wave, const std::string& where) {
  check_waveform(wave, where, "flow", ranges::flow_sample, ranges::mean_flow);
}

Inlet inlet_from_json(const nlohmann::json& j) {
  const std::string where = "inlet";
  if (!j.is_object()) throw InputError("\"inlet\" must be an object");
  if (!j.contains("vessel") || !j.at("vessel").is_number_integer())
    throw InputError("inlet: \"vessel\" must be a vessel id");
  // An id beyond the signed 64 bits of vessel ids names no vessel; say so with the number
  // as written rather than its wrapped value.
  if (j.at("vessel").is_number_unsigned() &&
      j.at("vessel").get<std::uint64_t>() >
          static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max()))
    throw InputError("inlet: unknown vessel " + j.at("vessel").dump());
  if (text(j, "type", "flow", where, "\"flow\"") != "flow")
    throw InputError("inlet: only \"type\": \"flow\" (a prescribed volume flow) is supported");
  if (!j.contains("waveform") || !j.at("waveform").is_object())
    throw InputError("inlet: missing \"waveform\"");
  Inlet inlet;
  inlet.vessel = j.at("vessel").get<std::int64_t>();
  inlet.waveform = waveform_from_json(j.at("waveform"), "inlet.waveform", "flow");
  check_waveform(inlet.waveform, "inlet.waveform");
  return inlet;
}

nlohmann::json to_json(const Outlet& o) {
  switch (o.type) {
    case BoundaryType::rcr:
      return {{"type", "RCR"}, {"R1", o.r1}, {"C", o.c}, {"R2", o.r2}, {"p_out", o.p_out}};
    case BoundaryType::resistance:
      return {{"type", "R"}, {"R", o.r}, {"p_out", o.p_out}};
    case BoundaryType::reflection:
      return {{"type", "reflection"}, {"coefficient", o.reflection}};
    case BoundaryType::flow:
    case BoundaryType::pressure:
      break;  // not outlet models
  }
  return {};
}

Outlet outlet_from_json(const nlohmann::json& j, const std::string& where) {
  if (!j.is_object() || !j.contains("type") || !j.at("type").is_string())
    throw InputError(where + ": an outlet needs a \"type\" (RCR, R or reflection)");
  Outlet o;
  const std::string type = j.at("type").get<std::string>();
  if (type == "RCR") {
    o.type = BoundaryType::rcr;
    o.r1 = in_range(j, "R1", ranges::rcr_part, where);
    o.c = in_range(j, "C", ranges::compliance, where);
    o.r2 = in_range(j, "R2", ranges::rcr_part, where);
    o.p_out = in_range_or(j, "p_out", ranges::pressure, 0.0, where);
    if (!(o.r1 + o.r2 >= ranges::resistance.min))
      throw InputError(where + ": RCR needs R1 + R2 >= " + format_number(ranges::resistance.min) +
                       " Pa s/m^3 (got " + format_number(o.r1 + o.r2) + ")");
  } else if (type == "R") {
    o.type = BoundaryType::resistance;
    o.r = in_range(j, "R", ranges::resistance, where);
    o.p_out = in_range_or(j, "p_out", ranges::pressure, 0.0, where);
  } else if (type == "reflection") {
    o.type = BoundaryType::reflection;
    o.reflection = in_range_or(j, "coefficient", ranges::reflection, 0.0, where);
  } else {
    throw InputError(where + ": unknown outlet type \"" + type + "\" (RCR, R or reflection)");
  }
  return o;
}

// ---- boundaries at nodes (format version 2) ------------------------------------------

nlohmann::json to_json(const NodeBoundary& b, std::int64_t node_id) {
  nlohmann::json j;
  switch (b.type) {
    case BoundaryType::flow:
    case BoundaryType::pressure: {
      const char* values = b.type == BoundaryType::flow ? "flow" : "pressure";
      j = {{"type", values}};
      if (b.waveform.shape == Waveform::Shape::constant) j[values] = b.waveform.mean;
      else j["waveform"] = to_json(b.waveform, values);
      break;
    }
    case BoundaryType::rcr:
    case BoundaryType::resistance:
    case BoundaryType::reflection: j = to_json(b.outlet); break;
  }
  j["node"] = node_id;
  if (!std::isnan(b.hematocrit)) j["hematocrit"] = b.hematocrit;
  return j;
}

NodeBoundary boundary_from_json(const nlohmann::json& j, const std::string& where, std::int64_t& node_id) {
  if (!j.is_object()) throw InputError(where + ": a boundary must be an object");
  if (!j.contains("node") || !j.at("node").is_number_integer() ||
      (j.at("node").is_number_unsigned() &&
       j.at("node").get<std::uint64_t>() > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())))
    throw InputError(where + ": \"node\" must be a node id");
  node_id = j.at("node").get<std::int64_t>();
  const std::string at = where + " (node " + std::to_string(node_id) + ")";
  NodeBoundary b;
  const std::string type = text(j, "type", "", at, "flow, pressure, RCR, R or reflection");
  if (type == "flow" || type == "pressure") {
    b.type = type == "flow" ? BoundaryType::flow : BoundaryType::pressure;
    const char* values = type == "flow" ? "flow" : "pressure";
    const FieldRange& range = type == "flow" ? ranges::flow_sample : ranges::pressure;
    if (j.contains(values) == j.contains("waveform"))
      throw InputError(at + ": a " + type + " boundary needs \"" + values + "\" (constant) or \"waveform\", one of them");
    if (j.contains(values)) b.waveform = Waveform::constant_value(number(j, values, at));
    else b.waveform = waveform_from_json(j.at("waveform"), at + ".waveform", values);
    check_waveform(b.waveform, at, values, range, range);
  } else if (type == "RCR" || type == "R" || type == "reflection") {
    b.type = type == "RCR" ? BoundaryType::rcr : type == "R" ? BoundaryType::resistance : BoundaryType::reflection;
    b.outlet = outlet_from_json(j, at);
  } else {
    throw InputError(at + ": \"type\" must be flow, pressure, RCR, R or reflection (got \"" + type + "\")");
  }
  if (j.contains("hematocrit")) {
    if (b.type != BoundaryType::flow && b.type != BoundaryType::pressure)
      throw InputError(at + ": \"hematocrit\" belongs to flow and pressure boundaries, where blood may enter");
    b.hematocrit = in_range(j, "hematocrit", ranges::hematocrit, at);
  }
  return b;
}

}  // namespace hemotree
