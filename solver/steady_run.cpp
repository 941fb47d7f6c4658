#include "solver/steady_run.hpp"

#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>

#include "cli/tool.hpp"
#include "cli/units.hpp"
#include "physics/rheology.hpp"
#include "solver/output_folder.hpp"
#include "solver/run_report.hpp"

namespace hemotree {

namespace {

// Flow into the network at every node through its boundary: what leaves the node by its
// vessels.
std::vector<double> boundary_inflow(const Network& net, const SteadyFlow& steady) {
  std::vector<double> inflow(net.node_count(), 0.0);
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    inflow[static_cast<std::size_t>(net.from[v])] += steady.flow[v];
    inflow[static_cast<std::size_t>(net.to[v])] -= steady.flow[v];
  }
  return inflow;
}

}  // namespace

CycleSummary steady_cycle(const Network& net, const Blood& blood, const SteadyFlow& steady) {
  CycleSummary cycle;
  cycle.vessels.resize(net.vessel_count());
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    VesselCycle& c = cycle.vessels[v];
    const double radius = net.diameter[v] / 2, area = std::numbers::pi * radius * radius;
    const double mu = apparent_viscosity(blood, net.diameter[v]);
    const double u = steady.flow[v] / area;
    c.mean_flow = c.peak_flow = c.least_flow = steady.flow[v];
    c.mean_pressure = c.systolic_pressure = c.diastolic_pressure =
        0.5 * (steady.node_pressure[static_cast<std::size_t>(net.from[v])] +
               steady.node_pressure[static_cast<std::size_t>(net.to[v])]);
    c.mean_wss = wall_shear_stress(mu, u, radius, blood.alpha);
    c.reynolds = blood.density * u * 2 * radius / mu;
    c.pwv_pressure = c.pwv_velocity = std::numeric_limits<double>::quiet_NaN();
  }
  const std::vector<double> inflow = boundary_inflow(net, steady);
  for (const NodeBoundary& b : node_boundaries(net)) {
    const double q = inflow[static_cast<std::size_t>(b.node)];
    (q > 0 ? cycle.inlet_mean_flow : cycle.outlets_mean_flow) += std::abs(q);
  }
  cycle.volume_change = 0;
  cycle.conservation_error = (cycle.inlet_mean_flow - cycle.outlets_mean_flow) / cycle.inlet_mean_flow;
  return cycle;
}

nlohmann::json boundary_results(const Network& net, const SteadyFlow& steady) {
  const std::vector<double> inflow = boundary_inflow(net, steady);
  nlohmann::json list = nlohmann::json::array();
  for (const NodeBoundary& b : node_boundaries(net)) {
    const auto i = static_cast<std::size_t>(b.node);
    list.push_back({{"node", net.node_id[i]},
                    {"type", to_string(b.type)},
                    {"flow", inflow[i]},
                    {"pressure", steady.node_pressure[i]}});
  }
  return list;
}

VesselTable steady_results(const Network& net, const CycleSummary& cycle) {
  const std::size_t n = net.vessel_count();
  VesselTable table = cycle_table(net, cycle, std::vector<std::uint8_t>(n, 0), {"steady"},
                                  std::vector<std::int64_t>(n, VesselTable::null_integer));
  for (const char* name : {"womersley", "pwv_elastic", "pwv_theory"})
    table.add_number(name, std::vector<double>(n, std::numeric_limits<double>::quiet_NaN()));
  return table;
}

void run_steady(const Network& net, const SteadyRunRequest& request) {
  Blood blood = net.blood.value_or(Blood{});
  if (request.rheology_override >= 0) blood.rheology = static_cast<Rheology>(request.rheology_override);
  OutputFolder folder(request.out_dir);
  const auto started = std::chrono::steady_clock::now();
  const SteadyFlow steady = solve_steady_flow(net, vessel_resistances(net, blood),
                                              net.inlet ? net.inlet->waveform.mean_value() : 0.0);
  const CycleSummary cycle = steady_cycle(net, blood, steady);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  const VesselTable results = steady_results(net, cycle);
  nlohmann::json run_info = {{"tool", "hemosolve"},
                             {"version", HEMOTREE_VERSION},
                             {"network", request.input},
                             {"mode", "steady"},
                             {"model", "steady"},
                             {"vessels_1d", 0},
                             {"vessels_0d", 0},
                             {"rheology", to_string(blood.rheology)},
                             {"mean_cell_volume", blood.mean_cell_volume},
                             {"status", "complete"},
                             {"cycles", 0},
                             {"wall_time", wall}};
  run_info["boundaries"] = boundary_results(net, steady);
  run_info["statistics"] = group_statistics(net, results);
  folder.open();
  const std::filesystem::path dir = folder.staging();
  write_summary(dir / "summary.json", run_info, results, cycle);
  write_vessel_table(dir / "vessels.csv", results);
  if (request.vtk) write_results_vtk(dir / "results.vtp", net, results, request.vtk_keep);
  folder.publish();
  if (!request.quiet)
    note("steady state of " + std::to_string(net.vessel_count()) + " vessels in " + format_quantity(wall, "s") +
         ": " + format_quantity(cycle.inlet_mean_flow, "nl/min") + " in through the boundaries; results in " +
         request.out_dir.string());
}

}  // namespace hemotree
