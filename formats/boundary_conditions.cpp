#include "formats/boundary_conditions.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "cli/errors.hpp"

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

// ---- JSON -----------------------------------------------------------------------------

namespace {

double number(const nlohmann::json& j, const char* key, const std::string& where) {
  if (!j.is_object() || !j.contains(key)) throw InputError(where + ": missing \"" + key + "\"");
  const auto& v = j.at(key);
  if (!v.is_number()) throw InputError(where + ": \"" + key + "\" must be a number");
  return v.get<double>();
}

double positive(const nlohmann::json& j, const char* key, const std::string& where) {
  const double v = number(j, key, where);
  if (!(v > 0)) throw InputError(where + ": \"" + key + "\" must be positive");
  return v;
}

double number_or(const nlohmann::json& j, const char* key, double fallback, const std::string& where) {
  return j.contains(key) ? number(j, key, where) : fallback;
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
  b.density = j.contains("density") ? positive(j, "density", where) : b.density;
  b.plasma_viscosity =
      j.contains("plasma_viscosity") ? positive(j, "plasma_viscosity", where) : b.plasma_viscosity;
  b.hematocrit = number_or(j, "hematocrit", b.hematocrit, where);
  if (!(b.hematocrit >= 0 && b.hematocrit < 1)) throw InputError("blood: hematocrit must lie in [0, 1)");
  b.alpha = number_or(j, "alpha", b.alpha, where);
  if (!(b.alpha > 1)) throw InputError("blood: alpha must exceed 1 (4/3 is a parabolic profile)");
  if (j.contains("rheology")) {
    const auto& r = j.at("rheology");
    if (r == "pries") b.rheology = Rheology::pries;
    else if (r == "newtonian") b.rheology = Rheology::newtonian;
    else throw InputError("blood: rheology must be \"pries\" or \"newtonian\"");
  }
  b.newtonian_viscosity = j.contains("newtonian_viscosity")
                              ? positive(j, "newtonian_viscosity", where) : b.newtonian_viscosity;
  b.pries_max_diameter = j.contains("pries_max_diameter")
                             ? positive(j, "pries_max_diameter", where) : b.pries_max_diameter;
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

Inlet inlet_from_json(const nlohmann::json& j) {
  const std::string where = "inlet";
  if (!j.is_object()) throw InputError("\"inlet\" must be an object");
  if (!j.contains("vessel") || !j.at("vessel").is_number_integer())
    throw InputError("inlet: \"vessel\" must be a vessel id");
  if (j.value("type", std::string("flow")) != "flow")
    throw InputError("inlet: only \"type\": \"flow\" (a prescribed volume flow) is supported");
  if (!j.contains("waveform") || !j.at("waveform").is_object())
    throw InputError("inlet: missing \"waveform\"");
  Inlet inlet;
  inlet.vessel = j.at("vessel").get<std::int64_t>();
  const auto& w = j.at("waveform");
  Waveform& wave = inlet.waveform;
  wave.period = positive(w, "period", "inlet.waveform");
  const std::string shape = w.value("shape", std::string());
  if (shape == "half_sine") {
    wave.shape = Waveform::Shape::half_sine;
    wave.systole = positive(w, "systole", "inlet.waveform");
    wave.mean = number(w, "mean", "inlet.waveform");
    if (wave.systole > wave.period) throw InputError("inlet.waveform: systole exceeds the period");
  } else if (shape == "table") {
    wave.shape = Waveform::Shape::table;
    try {
      wave.time = w.at("time").get<std::vector<double>>();
      wave.flow = w.at("flow").get<std::vector<double>>();
    } catch (const nlohmann::json::exception&) {
      throw InputError("inlet.waveform: a table needs number lists \"time\" and \"flow\"");
    }
    if (wave.time.size() < 2 || wave.time.size() != wave.flow.size())
      throw InputError("inlet.waveform: \"time\" and \"flow\" need the same length, at least 2");
    for (std::size_t k = 1; k < wave.time.size(); ++k)
      if (!(wave.time[k] > wave.time[k - 1]))
        throw InputError("inlet.waveform: times must increase");
    if (wave.time.front() < 0 || !(wave.time.back() < wave.period + wave.time.front()))
      throw InputError("inlet.waveform: times must lie within one period");
  } else {
    throw InputError("inlet.waveform: \"shape\" must be \"half_sine\" or \"table\"");
  }
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
    o.r1 = number(j, "R1", where);
    o.c = number(j, "C", where);
    o.r2 = number(j, "R2", where);
    o.p_out = number_or(j, "p_out", 0.0, where);
    if (!(o.r1 >= 0 && o.r2 >= 0 && o.r1 + o.r2 > 0 && o.c >= 0))
      throw InputError(where + ": RCR needs R1, R2 >= 0 with R1 + R2 > 0 and C >= 0");
  } else if (type == "R") {
    o.type = OutletType::resistance;
    o.r = positive(j, "R", where);
    o.p_out = number_or(j, "p_out", 0.0, where);
  } else if (type == "reflection") {
    o.type = OutletType::reflection;
    o.reflection = number_or(j, "coefficient", 0.0, where);
    if (!(std::abs(o.reflection) <= 1)) throw InputError(where + ": the reflection coefficient must lie in [-1, 1]");
  } else {
    throw InputError(where + ": unknown outlet type \"" + type + "\" (RCR, R or reflection)");
  }
  return o;
}

}  // namespace hemotree
