// What the files of openBF's reader and writer share (exchange/openbf_*.cpp; private to
// exchange/): openBF's physics where a model leaves something out, the YAML file's entries and
// their messages, the caps on what is read, and one vessel as openBF reads it.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <unordered_set>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "core/errors.hpp"
#include "exchange/openbf.hpp"
#include "formats/field_ranges.hpp"

namespace hemotree::openbf {

constexpr double unset = std::numeric_limits<double>::quiet_NaN();

// --- openBF's physics where the model leaves something out ---------------------------------

// openBF's wall thickness where a vessel gives no h0: Avolio's (1980) fit as openBF writes it
// (vessel.jl, the radius in metres): h0 = R (a e^(b R) + c e^(d R)).
inline double avolio_wall_thickness(double radius) {
  constexpr double a = 0.2802, b = -5.053e2, c = 0.1324, d = -0.1114e2;  // b, d [1/m]
  return radius * (a * std::exp(b * radius) + c * std::exp(d * radius));
}

// openBF's thin-wall law (Poisson ratio 1/2): at the reference area the wave speed is
// c0 = sqrt(beta / (2 rho)) with beta = 4/3 E h0 / R0, and the characteristic impedance is
// rho c0 / A0.
inline double characteristic_impedance(double density, double youngs_modulus, double wall, double radius) {
  const double c0 = std::sqrt(2.0 / 3.0 * youngs_modulus * wall / (density * radius));
  return density * c0 / (std::numbers::pi * radius * radius);
}

// That law as hemotree's p = p_ext + beta (sqrt(A) - sqrt(A0)): beta = 4 E h0 / (3 sqrt(pi) R0^2)
// [Pa/m] (openBF's own beta, sqrt(pi / A0) h0 E / (1 - 1/4), is this times sqrt(A0)).
inline double openbf_beta(double youngs_modulus, double wall, double radius) {
  return 4 * youngs_modulus * wall / (3 * std::sqrt(std::numbers::pi) * radius * radius);
}

// A velocity profile u ~ 1 - (r/R)^gamma (openBF's gamma_profile) has the momentum-flux
// coefficient alpha = (gamma + 2) / (gamma + 1); its friction 2 pi mu (gamma + 2) u / rho is
// hemotree's alpha / (alpha - 1) = gamma + 2.
inline double alpha_of_profile(double gamma) { return (gamma + 2) / (gamma + 1); }
inline double profile_of_alpha(double alpha) { return (2 - alpha) / (alpha - 1); }

// The accepted ranges of openBF's radii and profile exponent, from hemotree's diameters and
// alpha: alpha >= 1.001 is gamma <= 999, kept a unit inside so that alpha's rounding stays in.
constexpr FieldRange radius_range{ranges::diameter.min / 2, ranges::diameter.max / 2, "m"};
constexpr FieldRange profile_range{0, 998, ""};

// openBF's default profile exponent (vessel.jl: get(config, "gamma_profile", 2)): parabolic.
constexpr double default_profile = 2;

// --- the YAML file and its messages --------------------------------------------------------

struct Entry {
  std::string key;
  YAML::Mark mark;  // the key's
  YAML::Node value;
};

// The model's file, named in every message with the line at fault.
struct Source {
  std::string path;

  [[noreturn]] void fail(const YAML::Mark& mark, const std::string& what) const {
    if (mark.line < 0) throw InputError(path + ": " + what);
    throw InputError(path + ":" + std::to_string(mark.line + 1) + ": " + what);
  }
};

// A YAML mapping's entries in file order; refuses anything else, keys it does not know (with
// `unknown`, checked first, so that a file of many unknown keys is refused at the first) and
// keys given twice (a hash set: many keys cost linear time).
class Fields {
 public:
  // `unknown(key)`: the message for a key this mapping does not have, "" where it has it.
  using Unknown = std::function<std::string(const std::string&)>;

  Fields(const Source& source, const YAML::Node& node, std::string what, const Unknown& unknown = {})
      : source_(source), what_(std::move(what)), mark_(node.Mark()) {
    if (!node.IsMap()) source_.fail(mark_, what_ + " must be a mapping of keys to values");
    std::unordered_set<std::string> seen;
    for (const auto& item : node) {
      if (!item.first.IsScalar()) source_.fail(item.first.Mark(), what_ + ": a key must be a plain name");
      Entry e{item.first.as<std::string>(), item.first.Mark(), item.second};
      if (unknown) {
        const std::string why = unknown(e.key);
        if (!why.empty()) source_.fail(e.mark, what_ + ": " + why);
      }
      if (!seen.insert(e.key).second) source_.fail(e.mark, what_ + ": \"" + e.key + "\" given twice");
      entries_.push_back(std::move(e));
    }
  }

  const std::vector<Entry>& entries() const { return entries_; }
  const YAML::Mark& mark() const { return mark_; }
  const std::string& what() const { return what_; }

  const Entry* find(std::string_view key) const {
    for (const Entry& e : entries_)
      if (e.key == key) return &e;
    return nullptr;
  }
  // A key openBF spelled two ways (openBF 1.x wrote "gamma profile", 2.x "gamma_profile").
  const Entry* find(std::string_view key, std::string_view other) const {
    const Entry* a = find(key);
    const Entry* b = find(other);
    if (a && b) source_.fail(b->mark, what_ + ": \"" + b->key + "\" repeats \"" + a->key + "\"");
    return a ? a : b;
  }
  const Entry& require(std::string_view key) const {
    if (const Entry* e = find(key)) return *e;
    missing(std::string("\"") + std::string(key) + "\"");
  }
  [[noreturn]] void missing(const std::string& what) const { source_.fail(mark_, what_ + ": missing " + what); }

  [[noreturn]] void fail(const Entry& e, const std::string& what) const {
    source_.fail(e.mark, what_ + ": " + what);
  }

  double number(const Entry& e) const {
    double v = unset;
    if (!e.value.IsScalar() || !YAML::convert<double>::decode(e.value, v))
      fail(e, "\"" + e.key + "\" must be a number");
    return v;
  }
  double number(const Entry& e, const FieldRange& range) const {
    const double v = number(e);
    if (!range.contains(v)) fail(e, out_of_range(e.key, range, v));
    return v;
  }
  std::int64_t integer(const Entry& e) const {
    long long v = 0;
    if (!e.value.IsScalar() || !YAML::convert<long long>::decode(e.value, v))
      fail(e, "\"" + e.key + "\" must be an integer");
    return v;
  }
  bool boolean(const Entry& e) const {
    bool v = false;
    if (!e.value.IsScalar() || !YAML::convert<bool>::decode(e.value, v))
      fail(e, "\"" + e.key + "\" must be true or false");
    return v;
  }
  std::string text(const Entry& e) const {
    if (!e.value.IsScalar()) fail(e, "\"" + e.key + "\" must be a plain value");
    return e.value.as<std::string>();
  }

 private:
  const Source& source_;
  std::string what_;
  YAML::Mark mark_;
  std::vector<Entry> entries_;
};

// --- reading files with bounds ------------------------------------------------------------

// openBF's models and inlet tables are small text files (ADAN56's model is 30 kB, its table 22
// rows). Caps on what is read keep a wrong name (a device, a pipe, a file that never ends, a
// huge one) from taking memory and time without bound: far above any model, and below what
// yaml-cpp's nodes (tens of bytes of memory per byte of YAML) can hold comfortably.
constexpr std::size_t model_cap = std::size_t{8} << 20;   // bytes
constexpr std::size_t inlet_cap = std::size_t{64} << 20;  // bytes
constexpr std::size_t line_cap = 4096;                    // bytes of one inlet-table line

// The whole of a regular file of at most `cap` bytes. `named` names it in the IoError of a file
// that cannot be read; `kind` says what the file should be ("an inlet table").
std::string read_capped(const std::string& path, const std::string& named, const std::string& kind, std::size_t cap);

// The model: one YAML document (a second one is refused), parsed.
YAML::Node load_yaml(const std::string& path);

// --- one vessel, as openBF reads it --------------------------------------------------------

struct VesselModel {
  YAML::Mark mark;
  std::string label;
  std::int64_t sn = 0, tn = 0;
  double length = 0, rp = 0, rd = 0, youngs_modulus = 0;
  double wall = unset;                // h0, NaN: openBF's law
  double external_pressure = 0;       // Pext
  YAML::Mark external_pressure_mark;  // where Pext was given
  std::optional<double> profile;      // gamma_profile, or openBF 1.x's "gamma profile"
  bool profile_spaced = false;        // given as "gamma profile", which openBF 2.x does not read
  YAML::Mark profile_mark;
  // The outlet's keys, NaN where absent; `outlet` (wk2, wk3, reflection) only names the kind.
  double r1 = unset, r2 = unset, cc = unset, rt = unset, pout = unset;
  std::string outlet_kind;
  const Entry* first_outlet_key = nullptr;
  std::map<std::string, const Entry*, std::less<>> outlet_keys;
  // openBF 1.x put the inlet on a vessel: "inlet: Q" and "inlet file".
  bool inlet = false;
  std::string inlet_file;
  YAML::Mark inlet_mark;
};

inline bool has_outlet(const VesselModel& v) { return v.first_outlet_key != nullptr; }

// One entry of "network": its keys checked and read; the openBF settings it ignores go into
// `ignored`, and its entries into `keep`, which the VesselModel points into.
VesselModel read_vessel(const Source& source, const YAML::Node& node, std::size_t position,
                        std::set<std::string, std::less<>>& ignored, std::deque<Fields>& keep);

// Three significant digits, for a figure a note reports.
inline std::string three_digits(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", value);
  return format_number(std::strtod(text, nullptr));
}

// openBF's inlet file as hemotree's periodic flow table; `named_by` says where the model names it.
Waveform read_inlet_table(const std::string& path, const std::string& named_by, const ImportOptions& options);

}  // namespace hemotree::openbf
