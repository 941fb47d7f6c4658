#include "solver/probes.hpp"

#include <cstdlib>

#include "core/errors.hpp"
#include "core/setting_error.hpp"
#include "formats/output_stream.hpp"
#include "formats/quoting.hpp"

namespace hemotree {

Probe parse_probe(const std::string& text, const Network& net) {
  const auto colon = text.find(':');
  Probe p{0, 0, 0.5};
  try {
    std::size_t used = 0;
    p.id = std::stoll(text.substr(0, colon), &used);
    if (used != (colon == std::string::npos ? text.size() : colon)) throw std::invalid_argument("");
    if (colon != std::string::npos) {
      const std::string x = text.substr(colon + 1);
      p.x = std::stod(x, &used);
      if (used != x.size()) throw std::invalid_argument("");
    }
  } catch (const std::exception&) {
    throw SettingError("probe", placeholder("probe") + ": '" + printable(text) + "' is not ID or ID:x");
  }
  if (!(p.x >= 0 && p.x <= 1)) throw SettingError("probe", placeholder("probe") + ": x must lie in [0, 1] in '" + printable(text) + "'");
  const std::int64_t index = net.index_of(p.id);
  if (index < 0) throw SettingError("probe", placeholder("probe") + ": no vessel " + std::to_string(p.id));
  p.vessel = static_cast<std::size_t>(index);
  return p;
}

namespace {
std::string number(double v) {
  char text[32];
  return std::string(text, format_real(text, v));
}
}  // namespace

void ProbeRecorder::sample(const PulseSolver& solver) {
  add_row(solver.time(), [&](const Probe& p) {
    const double a = solver.area_at(p.vessel, p.x);
    // The law where the probe is: a tapered vessel's reference lumen changes along it.
    return Values{solver.law_at(p.vessel, p.x).pressure(a), solver.flow_at(p.vessel, p.x), a};
  });
}

void ProbeRecorder::add_row(double t, const std::function<Values(const Probe&)>& at) { add_row(t, at, column_); }

void ProbeRecorder::add_row(double t, const std::function<Values(const Probe&)>& at,
                            const std::function<double(std::size_t, const Probe&)>& column) {
  rows_ << number(t);
  for (const Probe& p : probes_) {
    const Values v = at(p);
    rows_ << ',' << number(v.pressure) << ',' << number(v.flow) << ',' << number(v.area) << ',' << number(v.flow / v.area);
    for (std::size_t j = 0; j < headers_.size(); ++j) rows_ << ',' << number(column(j, p));
  }
  rows_ << '\n';
}

std::vector<std::string> ProbeRecorder::column_names() const {
  std::vector<std::string> names{"t [s]"};
  for (const Probe& p : probes_) {
    const std::string at = " vessel " + std::to_string(p.id) + " x " + number(p.x);
    names.push_back("p" + at + " [Pa]");
    names.push_back("Q" + at + " [m^3/s]");
    names.push_back("A" + at + " [m^2]");
    names.push_back("u" + at + " [m/s]");
    for (const std::string& h : headers_) {
      const auto unit = h.find(" [");  // "name [unit]": the place goes between
      names.push_back(h.substr(0, unit) + at + (unit == std::string::npos ? "" : h.substr(unit)));
    }
  }
  return names;
}

std::vector<double> ProbeRecorder::values() const {
  std::vector<double> values;
  const std::string text = rows_.str();
  for (const char* at = text.c_str(); *at != '\0';) {
    char* end = nullptr;
    values.push_back(std::strtod(at, &end));
    at = *end == '\0' ? end : end + 1;  // past the comma or the newline
  }
  return values;
}

void ProbeRecorder::write(const std::filesystem::path& file) const {
  if (probes_.empty()) return;
  OutputStream out(file.string());
  const std::vector<std::string> names = column_names();
  for (std::size_t c = 0; c < names.size(); ++c) out << (c ? "," : "") << csv_field(names[c]);
  out << '\n' << rows_.str();
  out.commit();
}

}  // namespace hemotree
