#include "solver/transport_report.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "core/units.hpp"
#include "formats/topology.hpp"
#include "physics/phase_separation.hpp"

namespace hemotree {

namespace {

nlohmann::json tracer_block(const TracerSpec& t, const FlowTransport::TracerReport& moved) {
  const double amount = moved.amount;
  const double scale = std::max({moved.injected + moved.entered, amount, 1e-300});
  const bool bolus = t.shape == TracerSpec::Shape::bolus;
  return {{"name", t.name},
          {"carrier", to_string(t.carrier)},
          {"shape", bolus ? "bolus" : "step"},
          {"start", t.start},
          {"duration", bolus ? nlohmann::json(t.duration) : nlohmann::json(nullptr)},
          {"concentration", t.concentration},
          {"entered", moved.entered},
          {"injected", moved.injected},
          {"left", moved.left},
          {"in_network", amount},
          {"balance_error", (amount - (moved.entered + moved.injected - moved.left + moved.adjusted)) / scale}};
}

}  // namespace

void report_transport(const Network& net, const FlowTransport::Outcome& transport, const RedCellCycle& cells, double change,
                      double step, VesselTable& results, nlohmann::json& run_info) {
  const std::size_t tracers = transport.tracers.size();
  if (tracers > 0) {
    // Transit times are read against the generation (scripts/plot-results).
    const std::vector<std::int32_t> generation = generations_from_inlets(net);
    results.add_number("generation", std::vector<double>(generation.begin(), generation.end()));
    nlohmann::json list = nlohmann::json::array();
    for (std::size_t k = 0; k < tracers; ++k) {
      const std::string& name = transport.tracers[k].name;
      FlowTransport::TracerReport report = transport.reports[k];
      list.push_back(tracer_block(transport.tracers[k], report));
      IndicatorCurves::Landmarks& l = report.landmarks;
      results.add_number(name + "_arrival_time", std::move(l.arrival));
      results.add_number(name + "_peak_time", std::move(l.peak_time));
      results.add_number(name + "_peak", std::move(l.peak));
      results.add_number(name + "_mean_transit_time", std::move(l.mean_transit));
    }
    run_info["tracers"] = list;
  }
  if (!transport.red_cells || cells.discharge.empty()) return;
  std::vector<double> tube(net.vessel_count());
  const double scale = transport.pries_diameter_scale;
  for (std::size_t v = 0; v < tube.size(); ++v)
    tube[v] = tube_hematocrit(cells.discharge[v], net.mean_diameter(v), scale);
  results.add_number_view("discharge_hematocrit", cells.discharge);
  results.add_number("tube_hematocrit", std::move(tube));
  results.add_number_view("discharge_hematocrit_min", cells.lowest);
  results.add_number_view("discharge_hematocrit_max", cells.highest);
  nlohmann::json r = {{"cells", transport.cells},
                      {"steps", transport.advances},
                      {"step", step},
                      {"red_cells", cells.red_cells},
                      {"entered", cells.entered},
                      {"left", cells.left},
                      {"balance_error", cells.balance_error},
                      {"separating_nodes", cells.separating_nodes}};
  r["cycle_change"] = std::isnan(change) ? nlohmann::json(nullptr) : nlohmann::json(change);
  run_info["red_cell_transport"] = r;
}

std::string red_cell_line(const Network& net, const RedCellCycle& cells, double change) {
  std::size_t widest = 0;
  for (std::size_t v = 0; v < cells.discharge.size(); ++v)
    if (cells.highest[v] - cells.lowest[v] > cells.highest[widest] - cells.lowest[widest]) widest = v;
  std::ostringstream m;
  m << "red cells: discharge hematocrit " << format_rounded(*std::min_element(cells.discharge.begin(), cells.discharge.end()))
    << " to " << format_rounded(*std::max_element(cells.discharge.begin(), cells.discharge.end()))
    << " over the vessels; within the last cycle a vessel's swings by up to "
    << format_rounded(cells.highest[widest] - cells.lowest[widest]) << " (vessel " << net.id[widest] << ")";
  if (!std::isnan(change)) m << "; its cycle mean changed by up to " << format_rounded(change) << " from the cycle before";
  return m.str();
}

}  // namespace hemotree
