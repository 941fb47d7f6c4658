#include "solver/run_report.hpp"

#include <algorithm>
#include <deque>
#include <map>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "core/parallel_errors.hpp"
#include "formats/output_stream.hpp"
#include "formats/parallel_rows.hpp"
#include "formats/quoting.hpp"
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
  // At the vessel's middle: a tapered vessel's reference state changes along it.
  const TubeLaw law = solver.law_at(v, 0.5);
  const double d = net.is_tapered(v) ? 0.5 * (net.diameter[v] + net.distal_diameter[v]) : net.diameter[v];
  WaveTheory t;
  t.pwv_elastic = law.wave_speed(law.reference_area);
  t.womersley = womersley_number(d, solver.blood().density, solver.viscosity(std::numbers::pi / 4 * d * d), omega);
  t.pwv_theory = womersley_wave(t.pwv_elastic, t.womersley, omega).phase_velocity;
  return t;
}

VesselTable cycle_table(const Network& net, const CycleSummary& cycle, std::vector<std::uint8_t> model,
                        std::vector<std::string> model_labels, std::vector<std::int64_t> degree,
                        const std::vector<std::uint8_t>& wave_travels) {
  const std::size_t n = cycle.vessels.size();
  VesselTable table(n);
  std::vector<std::uint8_t> vessel_class(n);
  std::vector<std::string> class_names;
  for (int k = 0; k <= static_cast<int>(VesselClass::capillary); ++k)
    class_names.emplace_back(to_string(static_cast<VesselClass>(k)));
  for (std::size_t v = 0; v < n; ++v) vessel_class[v] = static_cast<std::uint8_t>(net.vessel_class[v]);
  table.add_integer_view("id", net.id);
  table.add_number_view("diameter", net.diameter);
  table.add_number_view("length", net.length);
  table.add_text("class", std::move(vessel_class), std::move(class_names));
  table.add_text("model", std::move(model), std::move(model_labels));
  table.add_integer("degree", std::move(degree));
  // The cycle's records are read where they lie (the caller keeps them); the pulsatility
  // index, computed from them, is held.
  const std::span<const VesselCycle> records(cycle.vessels);
  table.add_number_view("mean_flow", records, &VesselCycle::mean_flow);
  table.add_number_view("mean_pressure", records, &VesselCycle::mean_pressure);
  table.add_number_view("systolic_pressure", records, &VesselCycle::systolic_pressure);
  table.add_number_view("diastolic_pressure", records, &VesselCycle::diastolic_pressure);
  std::vector<double> pulsatility(n);
  for (std::size_t v = 0; v < n; ++v) pulsatility[v] = cycle.vessels[v].pulsatility_index();
  table.add_number("pulsatility_index", std::move(pulsatility));
  table.add_number_view("peak_flow", records, &VesselCycle::peak_flow);
  table.add_number_view("least_flow", records, &VesselCycle::least_flow);
  table.add_number_view("mean_wss", records, &VesselCycle::mean_wss);
  table.add_number_view("reynolds", records, &VesselCycle::reynolds);
  const double null = std::numeric_limits<double>::quiet_NaN();
  auto measured = [&](double WaveSpeeds::*speed) {
    std::vector<double> x(n, null);
    for (const auto& [v, speeds] : cycle.waves)
      if (wave_travels.empty() || wave_travels[v]) x[v] = speeds.*speed;
    return x;
  };
  table.add_number("pwv_pressure", measured(&WaveSpeeds::pressure));
  table.add_number("pwv_velocity", measured(&WaveSpeeds::velocity));
  return table;
}

VesselTable vessel_results(const Network& net, const PulseSolver& solver, const CycleSummary& cycle, double frequency,
                           int threads) {
  const double omega = 2 * std::numbers::pi * frequency;
  const std::size_t n = cycle.vessels.size();
  std::vector<std::int64_t> degree(n);
  std::vector<std::uint8_t> model(n), travels(n);
  std::vector<double> womersley(n), elastic(n), theory(n);
  // Each vessel its own (a Bessel series a vessel: about a second on one thread for the full tree).
  parallel_blocks(static_cast<std::int64_t>(n), threads, [&](std::int64_t first, std::int64_t last) {
    for (auto v = static_cast<std::size_t>(first); v < static_cast<std::size_t>(last); ++v) {
      degree[v] = solver.is_lumped(v) ? VesselTable::null_integer : solver.degree(v);
      model[v] = solver.is_lumped(v) ? 1 : 0;
      const WaveTheory t = wave_theory(solver, net, v, omega);
      womersley[v] = t.womersley;
      elastic[v] = t.pwv_elastic;
      theory[v] = t.pwv_theory;
      travels[v] = !solver.is_lumped(v);
    }
  });
  VesselTable table = cycle_table(net, cycle, std::move(model), {"1d", "0d"}, std::move(degree), travels);
  table.add_number("womersley", std::move(womersley));
  table.add_number("pwv_elastic", std::move(elastic));
  table.add_number("pwv_theory", std::move(theory));
  return table;
}

namespace {
// Where a top-level member `name` goes among the members of `head` (an object dumped with an
// indent of one, its closing brace cut off): before the first whose name sorts after it, as
// nlohmann::json's std::map orders them; npos: after the last. A member starts with a newline,
// one space and its quoted name (deeper members are indented further; strings escape newlines).
std::size_t member_place(const std::string& head, const std::string& name) {
  for (std::size_t at = head.find("\n \""); at != std::string::npos; at = head.find("\n \"", at + 1)) {
    const std::size_t begin = at + 3, end = head.find('"', begin);
    if (head.compare(begin, end - begin, name) > 0) return at;
  }
  return std::string::npos;
}

// The member as nlohmann::json dumps it with an indent of one at depth one.
void write_array(OutputStream& out, const SummaryArray& array, int threads) {
  constexpr auto replace = nlohmann::json::error_handler_t::replace;
  out << "\n \"" << array.name << "\": [";
  if (array.size > 0) out << "\n  ";
  write_rows(out, array.size, threads, ",\n  ", [&](std::string& text, std::size_t i) {
    std::string entry = array.entry(i).dump(1, ' ', false, replace);
    for (std::size_t at = entry.find('\n'); at != std::string::npos; at = entry.find('\n', at + 3)) entry.insert(at + 1, "  ");
    text += entry;
  });
  out << (array.size == 0 ? "]" : "\n ]");
}
}  // namespace

nlohmann::json summary_facts(const nlohmann::json& run, const CycleSummary& cycle) {
  nlohmann::json summary = run;
  summary["inlet_mean_flow"] = cycle.inlet_mean_flow;
  summary["outlets_mean_flow"] = cycle.outlets_mean_flow;
  // Relative to the inflow: null where nothing flowed in (there is no fraction to give).
  summary["mass_balance"] = cycle.inflow_measured && cycle.inlet_mean_flow > 0
                                ? nlohmann::json((cycle.inlet_mean_flow - cycle.outlets_mean_flow) / cycle.inlet_mean_flow)
                                : nlohmann::json(nullptr);
  summary["volume_change"] = cycle.volume_change;
  summary["conservation_error"] = cycle.conservation_error;
  summary["units"] = {{"flow", "m^3/s"}, {"pressure", "Pa"}, {"length", "m"}, {"wss", "Pa"},
                      {"speed", "m/s"}, {"frequency", "Hz"}};
  return summary;
}

void write_summary(const std::filesystem::path& file, const nlohmann::json& run, const VesselTable& vessels,
                   const CycleSummary& cycle, const SummaryArray& array, int threads) {
  const nlohmann::json summary = summary_facts(run, cycle);
  // The run's facts, then the vessels one by one, a line each: no string of the whole report
  // in memory (a million vessels are a gigabyte of text). Strings from outside (a file name
  // that is not UTF-8) must not stop the report: such bytes are written as U+FFFD.
  constexpr auto replace = nlohmann::json::error_handler_t::replace;
  std::string head = summary.dump(1, ' ', false, replace);
  head.resize(head.rfind('}'));  // the run's facts, open for the vessels
  while (!head.empty() && (head.back() == '\n' || head.back() == ' ')) head.pop_back();
  OutputStream out(file.string());
  if (array.name.empty()) {
    out << head;
  } else {
    if (summary.contains(array.name)) throw std::logic_error("summary.json: " + array.name + " given twice");
    const std::size_t place = member_place(head, array.name);
    if (place == std::string::npos) {
      out << head << ",";
      write_array(out, array, threads);
    } else {
      out << std::string_view(head).substr(0, place);
      write_array(out, array, threads);
      out << "," << std::string_view(head).substr(place);
    }
  }
  out << ",\n \"vessels\": [";
  if (vessels.rows() > 0) out << "\n  ";
  write_rows(out, vessels.rows(), threads, ",\n  ",
             [&](std::string& text, std::size_t v) { vessels.append_json_row(text, v); });
  out << (vessels.rows() == 0 ? "]\n}\n" : "\n ]\n}\n");
  out.commit();
}

nlohmann::json group_statistics(const Network& net, const VesselTable& vessels, int threads) {
  // Per group: how many vessels, and of each quantity the median, the 5th and 95th
  // percentiles (nearest rank) over the group's vessels where it is defined.
  static const char* quantities[] = {"mean_pressure", "pulsatility_index", "mean_flow", "mean_wss"};
  // values: scratch, kept from group to group (a fresh array a group and quantity was most of
  // the time: first touches of its pages).
  auto describe = [&](const std::vector<std::uint32_t>& members, std::vector<double>& values) {
    nlohmann::json g = {{"vessels", members.size()}};
    for (const char* q : quantities) {
      const VesselTable::Column* column = vessels.find(q);
      if (!column) continue;
      values.clear();
      for (const std::uint32_t v : members)
        if (const double x = column->number_at(v); std::isfinite(x)) values.push_back(x);
      if (values.empty()) continue;
      auto rank = [&](double f) {
        const auto k = static_cast<std::size_t>(std::llround(f * static_cast<double>(values.size() - 1)));
        std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
        return values[k];
      };
      const double p5 = rank(0.05), median = rank(0.5), p95 = rank(0.95);
      g[q] = {{"median", median}, {"p5", p5}, {"p95", p95}};
    }
    return g;
  };
  // The members of each group, in the vessels' order. A text column's groups by label (its
  // codes' labels looked up once, not a string-keyed map a vessel).
  auto by_label = [&](const VesselTable::Column& column) {
    std::map<std::string, std::vector<std::uint32_t>> groups;
    std::vector<std::vector<std::uint32_t>*> of_code;
    for (const std::string& label : column.labels) of_code.push_back(&groups[label]);
    for (std::size_t v = 0; v < vessels.rows(); ++v) of_code[column.code[v]]->push_back(static_cast<std::uint32_t>(v));
    std::erase_if(groups, [](const auto& group) { return group.second.empty(); });  // a label no vessel has
    return groups;
  };
  const auto by_class = by_label(*vessels.find("class")), by_model = by_label(*vessels.find("model"));
  std::map<std::int32_t, std::vector<std::uint32_t>> by_generation, by_diameter;
  for (std::size_t v = 0; v < vessels.rows(); ++v) {
    const auto row = static_cast<std::uint32_t>(v);
    if (!net.generation.empty()) by_generation[net.generation[v]].push_back(row);
    // Diameter bins a factor sqrt(2) wide: bin k holds [2^(k/2), 2^((k+1)/2)) um.
    by_diameter[static_cast<std::int32_t>(std::floor(2 * std::log2(net.diameter[v] * 1e6)))].push_back(row);
  }
  // Every group described in parallel (each its own: the same numbers for any count).
  std::vector<const std::vector<std::uint32_t>*> groups;
  for (const auto* grouping : {&by_class, &by_model})
    for (const auto& [name, members] : *grouping) groups.push_back(&members);
  for (const auto* grouping : {&by_generation, &by_diameter})
    for (const auto& [key, members] : *grouping) groups.push_back(&members);
  std::vector<nlohmann::json> described(groups.size());
  ParallelErrors errors;
#pragma omp parallel num_threads(threads) if (threads > 1)
  {
    std::vector<double> values;
#pragma omp for schedule(dynamic, 1)
    for (std::int64_t i = 0; i < static_cast<std::int64_t>(groups.size()); ++i)
      errors.guard(i, [&] { described[static_cast<std::size_t>(i)] = describe(*groups[static_cast<std::size_t>(i)], values); });
  }
  errors.rethrow();
  std::size_t next = 0;
  nlohmann::json out;
  for (const auto& [name, members] : by_class) out["by_class"][name] = std::move(described[next++]);
  for (const auto& [name, members] : by_model) out["by_model"][name] = std::move(described[next++]);
  // Generations and diameter bins as arrays in their order (an object's keys would sort as text).
  out["by_generation"] = nlohmann::json::array();
  for (const auto& [g, members] : by_generation) {
    nlohmann::json row = std::move(described[next++]);
    row["generation"] = g;
    out["by_generation"].push_back(row);
  }
  out["by_diameter"] = nlohmann::json::array();
  for (const auto& [k, members] : by_diameter) {
    nlohmann::json row = std::move(described[next++]);
    row["diameter_from"] = 1e-6 * std::exp2(k / 2.0);  // [m]
    row["diameter_to"] = 1e-6 * std::exp2((k + 1) / 2.0);
    out["by_diameter"].push_back(row);
  }
  return out;
}

void write_vessel_table(const std::filesystem::path& file, const VesselTable& vessels, int threads) {
  OutputStream out(file.string());
  const auto& columns = vessels.columns();
  if (vessels.rows() > 0) {
    for (std::size_t f = 0; f < columns.size(); ++f) out << (f ? "," : "") << csv_field(columns[f].name);
    out << '\n';
  }
  write_rows(out, vessels.rows(), threads, "", [&](std::string& text, std::size_t v) { vessels.append_csv_row(text, v); });
  out.commit();
}

void write_results_vtk(const std::filesystem::path& file, const Network& net, const VesselTable& vessels,
                       std::span<const std::uint8_t> keep) {
  // Every number per vessel but the geometry the PolyData has already (null -> NaN): the real
  // columns as they are (a view spaced apart copied), then the integer ones converted (a
  // deque: the fields point into it).
  std::deque<std::vector<double>> converted;
  std::vector<CellField> fields, integer_fields;
  for (const VesselTable::Column& c : vessels.columns()) {
    if (c.name == "id" || c.name == "diameter" || c.name == "length" || c.kind == VesselTable::Kind::text) continue;
    if (c.kind == VesselTable::Kind::number) {
      fields.push_back({c.name, c.numbers(converted.emplace_back())});
      continue;
    }
    std::vector<double>& x = converted.emplace_back(vessels.rows());
    for (std::size_t v = 0; v < x.size(); ++v) {
      const std::int64_t k = c.integer_at(v);
      x[v] = k == VesselTable::null_integer ? std::numeric_limits<double>::quiet_NaN() : static_cast<double>(k);
    }
    integer_fields.push_back({c.name, x});
  }
  fields.insert(fields.end(), integer_fields.begin(), integer_fields.end());
  // The vessel model as a number ParaView can colour by: 1 for 0D, 0 for 1D.
  const VesselTable::Column& model = *vessels.find("model");
  std::vector<double>& lumped = converted.emplace_back(vessels.rows());
  for (std::size_t v = 0; v < vessels.rows(); ++v) lumped[v] = model.labels[model.code[v]] == "0d" ? 1.0 : 0.0;
  fields.push_back({"model_0d", lumped});
  OutputStream out(file.string());
  write_vtk(net, out, fields, keep);
  out.commit();
}

void add_solution_frame(VtkTimeSeries& series, const PulseSolver& solver) {
  std::vector<double> area, flow, pressure;
  solver.sample_all(0.5, area, flow, &pressure);
  add_solution_frame(series, solver.time(), std::move(area), std::move(flow), std::move(pressure));
}

void add_solution_frame(VtkTimeSeries& series, double t, std::vector<double> area, std::vector<double> flow,
                        std::vector<double> pressure) {
  std::vector<double> velocity(area.size());
  for (std::size_t v = 0; v < area.size(); ++v) velocity[v] = flow[v] / area[v];
  series.add_frame(t, {{"p", pressure}, {"Q", flow}, {"A", area}, {"u", velocity}});
}

}  // namespace hemotree
