#include "formats/boundary_conditions.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <string>

#include "cli/errors.hpp"
#include "formats/field_ranges.hpp"

namespace hemotree {

std::string_view to_string(OutletType type) {
  switch (type) {
    case OutletType::rcr: return "RCR";
    case OutletType::resistance: return "R";
    case OutletType::reflection: return "reflection";
  }
  return "";
}

std::string_view to_string(Rheology rheology) {
  return rheology == Rheology::pries ? "pries" : "newtonian";
}

// ---- the inflow waveform --------------------------------------------------------------

double Waveform::peak() const {
  if (shape == Shape::half_sine) return mean * std::numbers::pi * period / (2 * systole);
  return *std::max_element(flow.begin(), flow.end());
}

double Waveform::operator()(double t) const {
  double phase = std::fmod(t, period);
  if (phase < 0) phase += period;
  if (shape == Shape::half_sine)
    return phase < systole ? peak() * std::sin(std::numbers::pi * phase / systole) : 0.0;
  // Linear interpolation, wrapping from the last sample to the first over one period.
  const auto k = static_cast<std::size_t>(std::upper_bound(time.begin(), time.end(), phase) - time.begin());
  const std::size_t n = time.size();
  const double t0 = k == 0 ? time[n - 1] - period : time[k - 1];
  const double q0 = k == 0 ? flow[n - 1] : flow[k - 1];
  const double t1 = k == n ? time[0] + period : time[k];
  const double q1 = k == n ? flow[0] : flow[k];
  return q0 + (q1 - q0) * (phase - t0) / (t1 - t0);
}

double Waveform::mean_flow() const {
  if (shape == Shape::half_sine) return mean;
  // Trapezoids over one period, with the wrap-around segment.
  const std::size_t n = time.size();
  double integral = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double t1 = k + 1 < n ? time[k + 1] : time[0] + period;
    const double q1 = k + 1 < n ? flow[k + 1] : flow[0];
    integral += 0.5 * (flow[k] + q1) * (t1 - time[k]);
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

std::vector<double> samples(const nlohmann::json& w, const char* key, const std::string& where) {
  const std::string message =
      where + ": a table needs number lists \"time\" and \"flow\"";
  if (!w.contains(key) || !w.at(key).is_array()) throw InputError(message);
  std::vector<double> values;
  values.reserve(w.at(key).size());
  for (const auto& v : w.at(key)) {
    if (!v.is_number()) throw InputError(message);
    values.push_back(v.get<double>());
  }
  return values;
}

std::string element(const char* key, std::size_t k) {
  return std::string(key) + "[" + std::to_string(k) + "]";
}

}  // namespace

nlohmann::json to_json(const Blood& b) {
  return {{"density", b.density},
          {"plasma_viscosity", b.plasma_viscosity},
          {"hematocrit", b.hematocrit},
          {"alpha", b.alpha},
          {"rheology", to_string(b.rheology)},
          {"newtonian_viscosity", b.newtonian_viscosity},
          {"pries_max_diameter", b.pries_max_diameter}};
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
  const std::string rheology =
      text(j, "rheology", "pries", where, "\"pries\" or \"newtonian\"");
  if (rheology == "pries") b.rheology = Rheology::pries;
  else if (rheology == "newtonian") b.rheology = Rheology::newtonian;
  else throw InputError("blood: \"rheology\" must be \"pries\" or \"newtonian\"");
  b.newtonian_viscosity =
      in_range_or(j, "newtonian_viscosity", ranges::viscosity, b.newtonian_viscosity, where);
  b.pries_max_diameter = in_range_or(j, "pries_max_diameter", ranges::pries_max_diameter,
                                     b.pries_max_diameter, where);
  return b;
}

nlohmann::json to_json(const Inlet& inlet) {
  const Waveform& w = inlet.waveform;
  nlohmann::json wave;
  if (w.shape == Waveform::Shape::half_sine)
    wave = {{"shape", "half_sine"}, {"period", w.period}, {"systole", w.systole}, {"mean", w.mean}};
  else
    wave = {{"shape", "table"}, {"period", w.period}, {"time", w.time}, {"flow", w.flow}};
  return {{"vessel", inlet.vessel}, {"type", "flow"}, {"waveform", wave}};
}

void check_waveform(const Waveform& wave, const std::string& where) {
  if (!ranges::period.contains(wave.period))
    throw InputError(where + ": " + out_of_range("period", ranges::period, wave.period));
  if (wave.shape == Waveform::Shape::half_sine) {
    if (!ranges::systole.contains(wave.systole))
      throw InputError(where + ": " + out_of_range("systole", ranges::systole, wave.systole));
    if (wave.systole > wave.period)
      throw InputError(where + ": \"systole\" (" + format_number(wave.systole) +
                       " s) exceeds the period (" + format_number(wave.period) + " s)");
    if (!ranges::mean_flow.contains(wave.mean))
      throw InputError(where + ": " + out_of_range("mean", ranges::mean_flow, wave.mean));
    return;
  }
  if (wave.time.size() < 2 || wave.time.size() != wave.flow.size())
    throw InputError(where + ": \"time\" and \"flow\" need the same length, at least 2");
  for (std::size_t k = 0; k < wave.flow.size(); ++k)
    if (!ranges::flow_sample.contains(wave.flow[k]))
      throw InputError(where + ": " +
                       out_of_range(element("flow", k), ranges::flow_sample, wave.flow[k]));
  for (std::size_t k = 1; k < wave.time.size(); ++k)
    if (!(wave.time[k] > wave.time[k - 1]))
      throw InputError(where + ": times must increase (" + element("time", k) + " = " +
                       format_number(wave.time[k]) + " s)");
  if (wave.time.front() < 0 || !(wave.time.back() < wave.period + wave.time.front()))
    throw InputError(where + ": times must lie within one period, from \"time\"[0] >= 0");
  const double mean = wave.mean_flow();
  if (!ranges::mean_flow.contains(mean))
    throw InputError(where + ": the table's mean flow must lie in " +
                     describe(ranges::mean_flow) + " (got " + format_number(mean) + ")");
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
  const auto& w = j.at("waveform");
  const std::string wave_where = "inlet.waveform";
  Waveform& wave = inlet.waveform;
  wave.period = number(w, "period", wave_where);
  const std::string shape =
      text(w, "shape", "", wave_where, "\"half_sine\" or \"table\"");
  if (shape == "half_sine") {
    wave.shape = Waveform::Shape::half_sine;
    wave.systole = number(w, "systole", wave_where);
    wave.mean = number(w, "mean", wave_where);
  } else if (shape == "table") {
    wave.shape = Waveform::Shape::table;
    wave.time = samples(w, "time", wave_where);
    wave.flow = samples(w, "flow", wave_where);
  } else {
    throw InputError(wave_where + ": \"shape\" must be \"half_sine\" or \"table\"");
  }
  check_waveform(wave, wave_where);
  return inlet;
}

nlohmann::json to_json(const Outlet& o) {
  switch (o.type) {
    case OutletType::rcr:
      return {{"type", "RCR"}, {"R1", o.r1}, {"C", o.c}, {"R2", o.r2}, {"p_out", o.p_out}};
    case OutletType::resistance:
      return {{"type", "R"}, {"R", o.r}, {"p_out", o.p_out}};
    case OutletType::reflection:
      return {{"type", "reflection"}, {"coefficient", o.reflection}};
  }
  return {};
}

Outlet outlet_from_json(const nlohmann::json& j, const std::string& where) {
  if (!j.is_object() || !j.contains("type") || !j.at("type").is_string())
    throw InputError(where + ": an outlet needs a \"type\" (RCR, R or reflection)");
  Outlet o;
  const std::string type = j.at("type").get<std::string>();
  if (type == "RCR") {
    o.type = OutletType::rcr;
    o.r1 = in_range(j, "R1", ranges::rcr_part, where);
    o.c = in_range(j, "C", ranges::compliance, where);
    o.r2 = in_range(j, "R2", ranges::rcr_part, where);
    o.p_out = in_range_or(j, "p_out", ranges::pressure, 0.0, where);
    if (!(o.r1 + o.r2 >= ranges::resistance.min))
      throw InputError(where + ": RCR needs R1 + R2 >= " + format_number(ranges::resistance.min) +
                       " Pa s/m^3 (got " + format_number(o.r1 + o.r2) + ")");
  } else if (type == "R") {
    o.type = OutletType::resistance;
    o.r = in_range(j, "R", ranges::resistance, where);
    o.p_out = in_range_or(j, "p_out", ranges::pressure, 0.0, where);
  } else if (type == "reflection") {
    o.type = OutletType::reflection;
    o.reflection = in_range_or(j, "coefficient", ranges::reflection, 0.0, where);
  } else {
    throw InputError(where + ": unknown outlet type \"" + type + "\" (RCR, R or reflection)");
  }
  return o;
}

}  // namespace hemotree
