#include "solver/tracer_spec.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cmath>
#include <sstream>

#include "core/errors.hpp"
#include "core/setting_error.hpp"
#include "formats/quoting.hpp"

namespace hemotree {

const char* to_string(TracerCarrier carrier) {
  switch (carrier) {
    case TracerCarrier::plasma:
      return "plasma";
    case TracerCarrier::cells:
      return "cells";
    case TracerCarrier::blood:
      break;
  }
  return "blood";
}

double TracerSpec::mean_over(double t0, double t1) const {
  const double end = shape == Shape::bolus ? start + duration : INFINITY;
  const double overlap = std::max(0.0, std::min(t1, end) - std::max(t0, start));
  return t1 > t0 ? concentration * overlap / (t1 - t0) : 0.0;
}

namespace {

[[noreturn]] void refuse(const std::string& spec, const std::string& what) {
  throw SettingError("tracer", placeholder("tracer") + " '" + printable(spec) + "': " + what);
}

double number(const std::string& spec, const std::string& key, const std::string& value, bool time) {
  std::size_t used = 0;
  double x = 0;
  try {
    x = std::stod(value, &used);
  } catch (const std::exception&) {
    refuse(spec, key + "=" + value + " is not a number");
  }
  std::string unit = value.substr(used);
  if (time && unit == "ms") x *= 1e-3;
  else if (!(unit.empty() || (time && unit == "s"))) refuse(spec, key + "=" + value + ": unknown unit '" + unit + "'" + (time ? " (s or ms)" : ""));
  if (!std::isfinite(x)) refuse(spec, key + "=" + value + " is not finite");
  return x;
}

// A tracer's name becomes column names (c_NAME, NAME_arrival_time, ...) in JSON, CSV and
// VTK, and is typed in scripts: a word of letters, digits, '_', '-' and '.', as a column name
// wants; the writers quote anything anyway, but a name that needs quoting is a name that
// breaks somebody's script.
constexpr std::size_t longest_name = 64;

void check_name(const std::string& spec, const std::string& name) {
  if (name.empty()) refuse(spec, "name= is empty: a word of letters, digits, '_', '-' and '.'");
  if (name.size() > longest_name)
    refuse(spec, "name is " + std::to_string(name.size()) + " characters long: at most " +
                     std::to_string(longest_name));
  for (const char c : name) {
    const auto byte = static_cast<unsigned char>(c);
    if (std::isalnum(byte) && byte < 0x80) continue;
    if (c == '_' || c == '-' || c == '.') continue;
    char shown[8];
    std::snprintf(shown, sizeof shown, "0x%02X", byte);
    refuse(spec, "name holds " + (byte >= 0x20 && byte < 0x7f ? "'" + std::string(1, c) + "'" : std::string("byte ") + shown) +
                     ": a word of letters, digits, '_', '-' and '.' (ASCII)");
  }
}

std::int64_t identifier(const std::string& spec, const std::string& value) {
  std::size_t used = 0;
  try {
    const long long id = std::stoll(value, &used);
    if (used == value.size()) return id;
  } catch (const std::exception&) {
  }
  refuse(spec, "at=" + value + ": expected inlet, node:ID or vessel:ID");
}

}  // namespace

TracerSpec parse_tracer(const std::string& spec, const Network& net, int ordinal) {
  TracerSpec t;
  t.name = "tracer" + std::to_string(ordinal);
  std::stringstream in(spec);
  std::string item;
  while (std::getline(in, item, ',')) {
    const auto eq = item.find('=');
    if (eq == std::string::npos) refuse(spec, "'" + item + "' is not key=value");
    const std::string key = item.substr(0, eq), value = item.substr(eq + 1);
    if (key == "name") {
      check_name(spec, value);
      t.name = value;
    } else if (key == "carrier") {
      if (value == "plasma") t.carrier = TracerCarrier::plasma;
      else if (value == "cells") t.carrier = TracerCarrier::cells;
      else if (value == "blood") t.carrier = TracerCarrier::blood;
      else refuse(spec, "carrier=" + value + ": plasma, cells or blood");
    } else if (key == "at") {
      if (value == "inlet") {
        t.place = TracerSpec::Place::inlet;
      } else if (value.rfind("node:", 0) == 0) {
        t.place = TracerSpec::Place::node;
        const std::int64_t id = identifier(spec, value.substr(5));
        t.at = -1;
        for (std::size_t n = 0; n < net.node_count() && t.at < 0; ++n)
          if (net.node_id[n] == id) t.at = static_cast<std::int64_t>(n);
        if (t.at < 0) refuse(spec, "at=" + value + ": no node " + std::to_string(id));
      } else if (value.rfind("vessel:", 0) == 0) {
        t.place = TracerSpec::Place::vessel;
        const std::int64_t id = identifier(spec, value.substr(7));
        t.at = net.index_of(id);
        if (t.at < 0) refuse(spec, "at=" + value + ": no vessel " + std::to_string(id));
      } else {
        refuse(spec, "at=" + value + ": expected inlet, node:ID or vessel:ID");
      }
    } else if (key == "shape") {
      if (value == "bolus") t.shape = TracerSpec::Shape::bolus;
      else if (value == "step") t.shape = TracerSpec::Shape::step;
      else refuse(spec, "shape=" + value + ": bolus or step");
    } else if (key == "start") {
      t.start = number(spec, key, value, true);
      if (t.start < 0) refuse(spec, "start=" + value + ": accepted range [0, inf) s");
    } else if (key == "duration") {
      t.duration = number(spec, key, value, true);
      if (!(t.duration > 0)) refuse(spec, "duration=" + value + ": accepted range (0, inf) s");
    } else if (key == "concentration") {
      t.concentration = number(spec, key, value, false);
      if (!(t.concentration > 0)) refuse(spec, "concentration=" + value + ": accepted range (0, inf)");
    } else {
      refuse(spec, "unknown key '" + key + "' (name, carrier, at, shape, start, duration, concentration)");
    }
  }
  return t;
}

namespace {
[[noreturn]] void refuse_twice(const std::string& name) {
  throw SettingError("tracer", placeholder("tracer") + ": two tracers named " + name);
}
}  // namespace

std::vector<TracerSpec> parse_tracers(const std::vector<std::string>& specs, const Network& net) {
  std::vector<TracerSpec> tracers;
  for (const std::string& spec : specs) tracers.push_back(parse_tracer(spec, net, static_cast<int>(tracers.size()) + 1));
  for (std::size_t i = 0; i < tracers.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (tracers[i].name == tracers[j].name)
        refuse_twice(tracers[i].name);
  return tracers;
}

}  // namespace hemotree
