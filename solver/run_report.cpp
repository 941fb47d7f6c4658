#include "solver/run_report.hpp"

#include <algorithm>
#include <charconv>
#include <map>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "formats/output_stream.hpp"
#include "physics/womersley.hpp"

namespace hemotree {

double pulse_frequency(const Waveform& w) {
  return w.shape == Waveform::Shape::half_sine ? 1 / w.systole : 1 / w.period;
}

double analysis_frequency(const Waveform& w) {
  const double harmonic = std::max(1.0, std::round(pulse_frequency(w) * w.period));
  return harmonic / w.period;
}

WaveTheory wave_theory(const PulseSolver& solver, const Network& net, std::size_t v, double omega) {
  const VesselLaw& law = solver.law(v);
  const double d = net.diameter[v];
  WaveTheory t;
  t.pwv_elastic = law.wave_speed(law.reference_area);
  t.womersley = womersley_number(d, solver.blood().density, solver.viscosity(std::numbers::pi / 4 * d * d), omega);
  t.pwv_theory = womersley_wave(t.pwv_elastic, t.womersley, omega).phase_velocity;
  return t;
}

namespace {
nlohmann::json finite_or_null(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }
}  // namespace

nlohmann::json vessel_results(const Network& net, const PulseSolver& solver, const CycleSummary& cycle,
                              double frequency) {
  const double omega = 2 * std::numbers::pi * frequency;
  nlohmann::json vessels = nlohmann::json::array();
  for (std::size_t v = 0; v < cycle.vessels.size(); ++v) {
    const VesselCycle& c = cycle.vessels[v];
    const WaveTheory theory = wave_theory(solver, net, v, omega);
    vessels.push_back({{"id", net.id[v]},
                       {"diameter", net.diameter[v]},
                       {"length", net.length[v]},
                       {"class", to_string(net.vessel_class[v])},
                       {"model", solver.is_lumped(v) ? "0d" : "1d"},
                       {"degree", solver.is_lumped(v) ? nlohmann::json(nullptr) : nlohmann::json(solver.degree(v))},
                       {"mean_flow", c.mean_flow},
                       {"mean_pressure", c.mean_pressure},
                       {"systolic_pressure", c.systolic_pressure},
                       {"diastolic_pressure", c.diastolic_pressure},
                       {"pulsatility_index", c.pulsatility_index()},
                       {"peak_flow", c.peak_flow},
                       {"least_flow", c.least_flow},
                       {"mean_wss", c.mean_wss},
                       {"reynolds", c.reynolds},
                       {"womersley", theory.womersley},
                       {"pwv_pressure", finite_or_null(c.pwv_pressure)},
                       {"pwv_velocity", finite_or_null(c.pwv_velocity)},
                       {"pwv_elastic", theory.pwv_elastic},
                       {"pwv_theory", theory.pwv_theory}});
  }
  return vessels;
}

void write_summary(const std::filesystem::path& file, const nlohmann::json& run, const nlohmann::json& vessels,
                   const CycleSummary& cycle) {
  nlohmann::json summary = run;
  summary["inlet_mean_flow"] = cycle.inlet_mean_flow;
  summary["outlets_mean_flow"] = cycle.outlets_mean_flow;
  summary["mass_balance"] = (cycle.inlet_mean_flow - cycle.outlets_mean_flow) / cycle.inlet_mean_flow;
  summary["volume_change"] = cycle.volume_change;
  summary["conservation_error"] = cycle.conservation_error;
  summary["units"] = {{"flow", "m^3/s"}, {"pressure", "Pa"}, {"length", "m"}, {"wss", "Pa"},
                      {"speed", "m/s"}, {"frequency", "Hz"}};
  // The run's facts, then the vessels one by one: no string of the whole report in memory
  // (a million vessels are a gigabyte of text). Strings from outside (a file name that is not
  // UTF-8) must not stop the report: such bytes are written as U+FFFD.
  constexpr auto replace = nlohmann::json::error_handler_t::replace;
  std::string head = summary.dump(1, ' ', false, replace);
  head.resize(head.rfind('}'));  // the run's facts, open for the vessels
  while (!head.empty() && (head.back() == '\n' || head.back() == ' ')) head.pop_back();
  OutputStream out(file.string());
  out << head << ",\n \"vessels\": [";
  for (std::size_t v = 0; v < vessels.size(); ++v)
    out << (v ? ",\n  " : "\n  ") << vessels[v].dump(-1, ' ', false, replace);
  out << (vessels.empty() ? "]\n}\n" : "\n ]\n}\n");
  out.commit();
}

nlohmann::json group_statistics(const Network& net, const nlohmann::json& vessels) {
  // Per group: how many vessels, and of each quantity the median, the 5th and 95th
  // percentiles (nearest rank) over the group's vessels where it is defined.
  static const char* quantities[] = {"mean_pressure", "pulsatility_index", "mean_flow", "mean_wss"};
  auto describe = [&](const std::vector<std::size_t>& members) {
    nlohmann::json g = {{"vessels", members.size()}};
    std::vector<double> values;
    for (const char* q : quantities) {
      values.clear();
      for (const std::size_t v : members)
        if (vessels[v][q].is_number()) values.push_back(vessels[v][q].get<double>());
      if (values.empty()) continue;
      std::sort(values.begin(), values.end());
      auto rank = [&](double f) { return values[static_cast<std::size_t>(std::llround(f * static_cast<double>(values.size() - 1)))]; };
      g[q] = {{"median", rank(0.5)}, {"p5", rank(0.05)}, {"p95", rank(0.95)}};
    }
    return g;
  };
  std::map<std::string, std::vector<std::size_t>> by_class, by_model;
  std::map<std::int32_t, std::vector<std::size_t>> by_generation, by_diameter;
  for (std::size_t v = 0; v < vessels.size(); ++v) {
    by_class[vessels[v]["class"].get<std::string>()].push_back(v);
    by_model[vessels[v].value("model", "1d")].push_back(v);
    if (!net.generation.empty()) by_generation[net.generation[v]].push_back(v);
    // Diameter bins a factor sqrt(2) wide: bin k holds [2^(k/2), 2^((k+1)/2)) um.
    by_diameter[static_cast<std::int32_t>(std::floor(2 * std::log2(net.diameter[v] * 1e6)))].push_back(v);
  }
  nlohmann::json out;
  for (const auto& [name, members] : by_class) out["by_class"][name] = describe(members);
  for (const auto& [name, members] : by_model) out["by_model"][name] = describe(members);
  // Generations and diameter bins as arrays in their order (an object's keys would sort as text).
  out["by_generation"] = nlohmann::json::array();
  for (const auto& [g, members] : by_generation) {
    nlohmann::json row = describe(members);
    row["generation"] = g;
    out["by_generation"].push_back(row);
  }
  out["by_diameter"] = nlohmann::json::array();
  for (const auto& [k, members] : by_diameter) {
    nlohmann::json row = describe(members);
    row["diameter_from"] = 1e-6 * std::exp2(k / 2.0);  // [m]
    row["diameter_to"] = 1e-6 * std::exp2((k + 1) / 2.0);
    out["by_diameter"].push_back(row);
  }
  return out;
}

void write_vessel_table(const std::filesystem::path& file, const nlohmann::json& vessels) {
  OutputStream out(file.string());
  if (vessels.empty()) {
    out.commit();
    return;
  }
  std::vector<std::string> names;
  for (const auto& [key, value] : vessels.front().items()) names.push_back(key);
  for (std::size_t f = 0; f < names.size(); ++f) out << (f ? "," : "") << names[f];
  out << '\n';
  char text[32];  // the shortest text that reads back to the same double, as summary.json's
  for (const auto& row : vessels) {
    for (std::size_t f = 0; f < names.size(); ++f) {
      if (f) out << ',';
      const auto& x = row[names[f]];
      if (x.is_number_integer()) out << x.get<std::int64_t>();
      else if (x.is_number()) out << std::string_view(text, std::to_chars(text, text + sizeof text, x.get<double>()).ptr);
      else if (x.is_string()) out << x.get<std::string>();  // class and model names: no commas
      // null: an empty field, which pandas and numpy read as NaN
    }
    out << '\n';
  }
  out.commit();
}

void write_results_vtk(const std::filesystem::path& file, const Network& net, const nlohmann::json& vessels,
                       std::span<const std::uint8_t> keep) {
  std::vector<std::string> names;
  for (const auto& [key, value] : vessels.front().items())
    if ((value.is_number() || value.is_null()) && key != "id" && key != "diameter" && key != "length")
      names.push_back(key);
  std::vector<std::vector<double>> columns(names.size(), std::vector<double>(vessels.size()));
  for (std::size_t v = 0; v < vessels.size(); ++v)
    for (std::size_t f = 0; f < names.size(); ++f) {
      const auto& x = vessels[v][names[f]];
      columns[f][v] = x.is_number() ? x.get<double>() : std::numeric_limits<double>::quiet_NaN();
    }
  std::vector<CellField> fields;
  for (std::size_t f = 0; f < names.size(); ++f) fields.push_back({names[f], columns[f]});
  // The vessel model as a number ParaView can colour by: 1 for 0D, 0 for 1D.
  std::vector<double> lumped(vessels.size());
  for (std::size_t v = 0; v < vessels.size(); ++v) lumped[v] = vessels[v].value("model", "1d") == "0d" ? 1.0 : 0.0;
  fields.push_back({"model_0d", lumped});
  OutputStream out(file.string());
  write_vtk(net, out, fields, keep);
  out.commit();
}

void add_solution_frame(VtkTimeSeries& series, const PulseSolver& solver) {
  std::vector<double> area, flow;
  solver.sample_all(0.5, area, flow);
  std::vector<double> pressure(area.size()), velocity(area.size());
  for (std::size_t v = 0; v < area.size(); ++v) {
    pressure[v] = solver.law(v).pressure(area[v]);
    velocity[v] = flow[v] / area[v];
  }
  series.add_frame(solver.time(), {{"p", pressure}, {"Q", flow}, {"A", area}, {"u", velocity}});
}

}  // namespace hemotree
