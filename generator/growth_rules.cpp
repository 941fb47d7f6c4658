#include "generator/growth_rules.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "core/errors.hpp"

namespace hemotree {

namespace {

std::string um(double metres) {
  std::ostringstream s;
  s << metres * 1e6 << " um";
  return s.str();
}

// Kamiya & Takahashi (2007) calibrations, as the paper describes them (ERRATA.md s. 2).
constexpr FractalCalibration proximal{6e-3, 250e-6, 200e-6, 1.75};     // 12 mm - 500 um, 200 ml
constexpr FractalCalibration distal{300e-6, 4e-6, 0.043e-6, 1.75};     // 600 - 8 um, 0.043 ml

LengthLaw power_law(double gamma, const FractalCalibration& c) {
  LengthLaw l;
  l.kind = LengthLaw::Kind::power;
  l.gamma = gamma;
  l.calibration = c;
  l.zeta = length_scale_zeta(c, gamma);
  return l;
}

WallLaw ratio(double h_over_d) {
  WallLaw w;
  w.kind = WallLaw::Kind::ratio;
  w.h_over_d = h_over_d;
  return w;
}

// h = R (0.2802 e^(-5.053 R/cm) + 0.1324 e^(-0.1114 R/cm)), the empirical law behind
// Table 1's artery ratios (18.6 % at 600 um, 8.2 % at 8 mm); R in metres here.
WallLaw arterial_exponential() {
  WallLaw w;
  w.kind = WallLaw::Kind::exponential;
  w.a = 0.2802;
  w.b = -505.3;
  w.c = 0.1324;
  w.d = -11.14;
  return w;
}

}  // namespace

double WallLaw::thickness(double diameter) const {
  if (kind == Kind::ratio) return h_over_d * diameter;
  const double r = diameter / 2;
  return r * (a * std::exp(b * r) + c * std::exp(d * r));
}

const BranchingRange& GrowthRules::range_for(double diameter) const {
  for (const BranchingRange& r : ranges)
    if (diameter >= r.diameter_min && diameter < r.diameter_max) return r;
  throw InputError("diameter " + um(diameter) + " lies outside every range of the growth rules");
}

double GrowthRules::youngs_modulus(double diameter) const {
  const auto& d = modulus_diameter;
  const auto& e = modulus_value;
  if (diameter <= d.front()) return e.front();
  if (diameter >= d.back()) return e.back();
  const auto k = static_cast<std::size_t>(std::upper_bound(d.begin(), d.end(), diameter) - d.begin());
  const double t = (diameter - d[k - 1]) / (d[k] - d[k - 1]);
  return e[k - 1] + t * (e[k] - e[k - 1]);
}

GrowthRules default_rules() {
  GrowthRules r;
  BranchingRange artery{500e-6, 2.6e-2, 0.50, 0.98, 2.7, power_law(0.95, proximal)};
  // Table 2 prints (m, gamma) = (2.7, 0.95) with zeta = 1453 here, row 1's values beside the
  // distal zeta: an inconsistent row (ERRATA.md s. 2). gamma = 1.25 with the distal
  // calibration keeps lengths continuous at 500 um, and the paper's m = d_f + gamma then
  // gives m = 3, which reproduces its small-artery and arteriole counts within 3 %.
  BranchingRange small_artery{100e-6, 500e-6, 0.80, 0.95, 3.0, power_law(1.25, distal)};
  BranchingRange arteriole{10e-6, 100e-6, 0.65, 0.79, 3.0, power_law(1.25, distal)};
  LengthLaw capillary_length;
  capillary_length.kind = LengthLaw::Kind::uniform;
  capillary_length.min = 500e-6;
  capillary_length.max = 700e-6;
  BranchingRange capillary{0.0, 10e-6, 0.75, 0.95, 3.5, capillary_length};
  r.ranges = {capillary, arteriole, small_artery, artery};

  r.wall[static_cast<int>(VesselClass::artery)] = arterial_exponential();
  r.wall[static_cast<int>(VesselClass::small_artery)] = arterial_exponential();
  r.wall[static_cast<int>(VesselClass::arteriole)] = ratio(0.325);
  r.wall[static_cast<int>(VesselClass::capillary)] = ratio(0.10);

  // Knots at the centres of the cited ranges (docs/tree-statistics.md, sources there):
  // <= 15 um 160 kPa, 15-25 um 260 kPa, 25-100 um 630 kPa (Salotto et al. 1986),
  // 200-300 um 300 kPa (Guidoboni et al. 2014), 1 mm 225 kPa (Boileau et al. 2015).
  r.modulus_diameter = {15e-6, 20e-6, 62.5e-6, 250e-6, 1e-3};
  r.modulus_value = {160e3, 260e3, 630e3, 300e3, 225e3};
  r.stop = StopRule::mean_daughter;
  return r;
}

void validate(const GrowthRules& rules) {
  auto fail = [](const std::string& m) { throw InputError("growth rules: " + m); };
  if (rules.ranges.empty()) fail("no diameter ranges");
  for (std::size_t i = 0; i < rules.ranges.size(); ++i) {
    const BranchingRange& r = rules.ranges[i];
    const std::string name = "range " + std::to_string(i) + " [" + um(r.diameter_min) + ", " +
                             um(r.diameter_max) + ")";
    if (!(r.diameter_min >= 0) || !(r.diameter_max > r.diameter_min))
      fail(name + ": diameter_max must exceed diameter_min >= 0");
    if (!(r.kappa_min > 0 && r.kappa_min < 1) || !(r.kappa_max > 0 && r.kappa_max < 1))
      fail(name + ": kappa_min and kappa_max must lie in (0, 1)");
    if (r.kappa_min > r.kappa_max) fail(name + ": kappa_min exceeds kappa_max");
    if (!(r.murray_exponent >= 1 && r.murray_exponent <= 10))
      fail(name + ": murray_exponent must lie in [1, 10] (2.7-3.5 in the paper)");
    // Both daughters must be thinner than their parent by at least 0.1 %: the size estimate's
    // grid step, and what keeps growth finite (kappa -> 1 or m -> infinity gives a second
    // daughter as wide as its parent, a branch that never ends).
    const double widest_second =
        std::pow(1.0 - std::pow(r.kappa_min, r.murray_exponent), 1.0 / r.murray_exponent);
    if (r.kappa_max > 0.999 || !(widest_second <= 0.999))
      fail(name + ": kappa_max and the second daughter (1 - kappa_min^m)^(1/m) must be at most "
                  "0.999 of the parent's diameter (got " + std::to_string(r.kappa_max) + " and " +
                  std::to_string(widest_second) + ")");
    const LengthLaw& l = r.length;
    if (l.kind == LengthLaw::Kind::power && !(l.zeta > 0 && std::isfinite(l.gamma)))
      fail(name + ": the length law needs zeta > 0 and a finite gamma");
    if (l.kind == LengthLaw::Kind::uniform && !(l.min > 0 && l.max >= l.min))
      fail(name + ": the uniform length law needs 0 < min <= max");
    if (i > 0) {
      const double previous_max = rules.ranges[i - 1].diameter_max;
      if (r.diameter_min < previous_max) fail(name + " overlaps the range below it");
      if (r.diameter_min > previous_max) fail(name + " leaves a gap below it, down to " + um(previous_max));
    }
  }
  for (const WallLaw& w : rules.wall) {
    if (w.kind == WallLaw::Kind::ratio && !(w.h_over_d > 0)) fail("wall h_over_d must be positive");
    if (w.kind == WallLaw::Kind::exponential && !(w.thickness(10e-6) > 0))
      fail("the exponential wall law gives a non-positive thickness");
  }
  const auto& d = rules.modulus_diameter;
  const auto& e = rules.modulus_value;
  if (d.empty() || d.size() != e.size()) fail("youngs_modulus needs as many diameters as moduli, at least one");
  for (std::size_t k = 0; k < d.size(); ++k) {
    if (!(e[k] > 0)) fail("youngs_modulus values must be positive");
    if (k > 0 && !(d[k] > d[k - 1])) fail("youngs_modulus diameters must increase");
  }
}

std::string_view to_string(StopRule rule) {
  switch (rule) {
    case StopRule::smaller_daughter: return "smaller_daughter";
    case StopRule::mean_daughter: return "mean_daughter";
    case StopRule::larger_daughter: return "larger_daughter";
    case StopRule::parent: return "parent";
  }
  return "";
}

// ---- JSON ---------------------------------------------------------------------------

namespace {

nlohmann::json to_json(const LengthLaw& l) {
  if (l.kind == LengthLaw::Kind::uniform) return {{"law", "uniform"}, {"min", l.min}, {"max", l.max}};
  nlohmann::json j = {{"law", "power"}, {"gamma", l.gamma}};
  if (l.calibration) {
    const FractalCalibration& c = *l.calibration;
    j["zeta_calibration"] = {{"radius_max", c.radius_max}, {"radius_min", c.radius_min},
                             {"volume", c.volume}, {"fractal_dimension", c.fractal_dimension}};
  } else {
    j["zeta"] = l.zeta;
  }
  return j;
}

nlohmann::json to_json(const WallLaw& w) {
  if (w.kind == WallLaw::Kind::ratio) return {{"law", "ratio"}, {"h_over_d", w.h_over_d}};
  return {{"law", "exponential"}, {"a", w.a}, {"b", w.b}, {"c", w.c}, {"d", w.d}};
}

double number(const nlohmann::json& j, const char* key, const std::string& where) {
  if (!j.is_object() || !j.contains(key)) throw InputError(where + ": missing \"" + key + "\"");
  if (!j.at(key).is_number()) throw InputError(where + ": \"" + key + "\" must be a number");
  return j.at(key).get<double>();
}

std::string text(const nlohmann::json& j, const char* key, const std::string& where) {
  if (!j.is_object() || !j.contains(key) || !j.at(key).is_string())
    throw InputError(where + ": \"" + key + "\" must be a string");
  return j.at(key).get<std::string>();
}

LengthLaw length_from_json(const nlohmann::json& j, const std::string& where) {
  LengthLaw l;
  const std::string law = text(j, "law", where);
  if (law == "uniform") {
    l.kind = LengthLaw::Kind::uniform;
    l.min = number(j, "min", where);
    l.max = number(j, "max", where);
    return l;
  }
  if (law != "power") throw InputError(where + ": unknown length law \"" + law + "\"");
  l.gamma = number(j, "gamma", where);
  const bool has_zeta = j.contains("zeta"), has_calibration = j.contains("zeta_calibration");
  if (has_zeta == has_calibration)
    throw InputError(where + ": give exactly one of \"zeta\" and \"zeta_calibration\"");
  if (has_zeta) {
    l.zeta = number(j, "zeta", where);
    return l;
  }
  const auto& c = j.at("zeta_calibration");
  const std::string cw = where + ".zeta_calibration";
  FractalCalibration f{number(c, "radius_max", cw), number(c, "radius_min", cw),
                       number(c, "volume", cw), number(c, "fractal_dimension", cw)};
  if (!(f.radius_max > f.radius_min && f.radius_min > 0 && f.volume > 0 &&
        f.fractal_dimension > 0 && f.fractal_dimension != 2))
    throw InputError(cw + ": needs radius_max > radius_min > 0, volume > 0, 0 < d_f != 2");
  l.calibration = f;
  l.zeta = length_scale_zeta(f, l.gamma);
  return l;
}

WallLaw wall_from_json(const nlohmann::json& j, const std::string& where) {
  WallLaw w;
  const std::string law = text(j, "law", where);
  if (law == "ratio") {
    w.kind = WallLaw::Kind::ratio;
    w.h_over_d = number(j, "h_over_d", where);
  } else if (law == "exponential") {
    w.kind = WallLaw::Kind::exponential;
    w.a = number(j, "a", where);
    w.b = number(j, "b", where);
    w.c = number(j, "c", where);
    w.d = number(j, "d", where);
  } else {
    throw InputError(where + ": unknown wall law \"" + law + "\"");
  }
  return w;
}

}  // namespace

nlohmann::json to_json(const GrowthRules& rules) {
  nlohmann::json ranges = nlohmann::json::array();
  for (const BranchingRange& r : rules.ranges)
    ranges.push_back({{"diameter_min", r.diameter_min}, {"diameter_max", r.diameter_max},
                      {"kappa_min", r.kappa_min}, {"kappa_max", r.kappa_max},
                      {"murray_exponent", r.murray_exponent}, {"length", to_json(r.length)}});
  nlohmann::json wall = nlohmann::json::object();
  for (int c = 0; c < vessel_class_count; ++c)
    wall[std::string(to_string(static_cast<VesselClass>(c)))] = to_json(rules.wall[c]);
  return {{"ranges", ranges},
          {"wall_thickness", wall},
          {"youngs_modulus", {{"diameter", rules.modulus_diameter}, {"modulus", rules.modulus_value}}},
          {"stop", to_string(rules.stop)}};
}

GrowthRules rules_from_json(const nlohmann::json& j) {
  // Anything not given keeps its default, so a rules file can change one thing.
  GrowthRules r = default_rules();
  if (!j.is_object()) throw InputError("growth rules must be a JSON object");
  if (j.contains("ranges")) {
    const auto& list = j.at("ranges");
    if (!list.is_array()) throw InputError("growth rules: \"ranges\" must be a list");
    r.ranges.clear();
    for (std::size_t i = 0; i < list.size(); ++i) {
      const auto& e = list[i];
      const std::string where = "growth rules: ranges[" + std::to_string(i) + "]";
      BranchingRange b;
      b.diameter_min = number(e, "diameter_min", where);
      b.diameter_max = number(e, "diameter_max", where);
      b.kappa_min = number(e, "kappa_min", where);
      b.kappa_max = number(e, "kappa_max", where);
      b.murray_exponent = number(e, "murray_exponent", where);
      if (!e.contains("length")) throw InputError(where + ": missing \"length\"");
      b.length = length_from_json(e.at("length"), where + ".length");
      r.ranges.push_back(b);
    }
    std::sort(r.ranges.begin(), r.ranges.end(),
              [](const auto& a, const auto& b) { return a.diameter_min < b.diameter_min; });
  }
  if (j.contains("wall_thickness")) {
    const auto& w = j.at("wall_thickness");
    if (!w.is_object()) throw InputError("growth rules: \"wall_thickness\" must be an object");
    for (const auto& [name, law] : w.items()) {
      auto c = parse_vessel_class(name);
      if (!c) throw InputError("growth rules: wall_thickness: unknown class \"" + name + "\"");
      r.wall[static_cast<int>(*c)] = wall_from_json(law, "growth rules: wall_thickness." + name);
    }
  }
  if (j.contains("youngs_modulus")) {
    const auto& e = j.at("youngs_modulus");
    try {
      r.modulus_diameter = e.at("diameter").get<std::vector<double>>();
      r.modulus_value = e.at("modulus").get<std::vector<double>>();
    } catch (const nlohmann::json::exception&) {
      throw InputError("growth rules: youngs_modulus needs lists \"diameter\" and \"modulus\"");
    }
  }
  if (j.contains("stop")) {
    const std::string s = text(j, "stop", "growth rules");
    bool known = false;
    for (StopRule rule : {StopRule::smaller_daughter, StopRule::mean_daughter,
                          StopRule::larger_daughter, StopRule::parent})
      if (s == to_string(rule)) {
        r.stop = rule;
        known = true;
      }
    if (!known)
      throw InputError("growth rules: \"stop\" must be smaller_daughter, mean_daughter, "
                       "larger_daughter or parent");
  }
  validate(r);
  return r;
}

GrowthRules read_rules(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw IoError("cannot open rules file " + path);
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    // Any exception of parsing is the file's fault, not an internal error: a syntax error,
    // a number beyond a double ("1e3081", out_of_range), whatever a later nlohmann adds.
    throw InputError(path + ": " + e.what());
  }
  try {
    return rules_from_json(j);
  } catch (const InputError& e) {
    throw InputError(path + ": " + e.what());
  }
}

}  // namespace hemotree
