#include "solver/steady_run.hpp"

#include <algorithm>
#include <memory>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <utility>

#include "core/errors.hpp"
#include "core/units.hpp"
#include "distributed/steady_hematocrit_over_ranks.hpp"
#include "distributed/steady_on_slices.hpp"
#include "distributed/steady_over_ranks.hpp"
#include "formats/network_io.hpp"
#include "formats/run_boundaries.hpp"
#include "physics/rheology.hpp"
#include "solver/output_folder.hpp"
#include "mpi/session.hpp"
#include "physics/phase_separation.hpp"
#include "solver/run_report.hpp"
#include "steady/steady_hematocrit.hpp"

namespace hemotree {

namespace {

// The coupled flow-hematocrit iteration: passes and the change (hematocrit, and flow relative
// to the largest) below which it has converged.
constexpr int red_cell_iterations = 1000;
constexpr double red_cell_tolerance = 1e-9;

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

// The run's boundaries in node order (node_boundaries' order: summary.json's), as places in
// the view: a tree's two million outlets are not copied as conditions (300 MB, and the
// copying was a tenth of --linear's time on the full tree).
std::vector<std::uint32_t> in_node_order(const RunBoundaries& boundaries) {
  std::vector<std::pair<std::int32_t, std::uint32_t>> key(boundaries.size());
  for (std::size_t i = 0; i < key.size(); ++i) key[i] = {boundaries.node(i), static_cast<std::uint32_t>(i)};
  std::sort(key.begin(), key.end());  // one boundary a node (RunBoundaries checks it)
  std::vector<std::uint32_t> order(key.size());
  for (std::size_t k = 0; k < key.size(); ++k) order[k] = key[k].second;
  return order;
}

}  // namespace

CycleSummary steady_cycle(const Network& net, const Blood& blood, const SteadyFlow& steady,
                          const std::vector<double>* hematocrit) {
  CycleSummary cycle;
  cycle.vessels.resize(net.vessel_count());
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    VesselCycle& c = cycle.vessels[v];
    const double radius = net.diameter[v] / 2, area = std::numbers::pi * radius * radius;
    Blood own = blood;  // the vessel's own hematocrit where red cells separate
    if (hematocrit) own.hematocrit = (*hematocrit)[v];
    const double mu = apparent_viscosity(own, net.diameter[v]);
    const double u = steady.flow[v] / area;
    c.mean_flow = c.peak_flow = c.least_flow = steady.flow[v];
    c.mean_pressure = c.systolic_pressure = c.diastolic_pressure =
        0.5 * (steady.node_pressure[static_cast<std::size_t>(net.from[v])] +
               steady.node_pressure[static_cast<std::size_t>(net.to[v])]);
    c.mean_wss = wall_shear_stress(mu, u, radius, blood.alpha);
    c.reynolds = blood.density * u * 2 * radius / mu;
  }
  add_boundary_flows(net, steady, cycle);
  return cycle;
}

void add_boundary_flows(const Network& net, const SteadyFlow& steady, CycleSummary& cycle) {
  const std::vector<double> inflow = boundary_inflow(net, steady);
  const RunBoundaries boundaries(net);
  for (const std::uint32_t i : in_node_order(boundaries)) {
    const double q = inflow[static_cast<std::size_t>(boundaries.node(i))];
    (q > 0 ? cycle.inlet_mean_flow : cycle.outlets_mean_flow) += std::abs(q);
  }
  cycle.volume_change = 0;
  // Where nothing flows (zero boundary flows, equal pressures) nothing is lost either.
  const double scale = std::max(cycle.inlet_mean_flow, cycle.outlets_mean_flow);
  cycle.conservation_error = scale > 0 ? (cycle.inlet_mean_flow - cycle.outlets_mean_flow) / scale : 0.0;
}

SummaryArray boundary_results(const Network& net, const SteadyFlow& steady) {
  // Shared by the entries (the function outlives this call: write_summary calls it).
  auto boundaries = std::make_shared<const RunBoundaries>(net);
  auto order = std::make_shared<const std::vector<std::uint32_t>>(in_node_order(*boundaries));
  auto inflow = std::make_shared<const std::vector<double>>(boundary_inflow(net, steady));
  auto pressure = std::make_shared<const std::vector<double>>(steady.node_pressure);
  const Blood blood = net.blood.value_or(Blood{});
  return {"boundaries", order->size(), [&net, boundaries, order, inflow, pressure, blood](std::size_t k) {
            const NodeBoundary b = (*boundaries)[(*order)[k]];
            const auto i = static_cast<std::size_t>(b.node);
            nlohmann::json entry = {{"node", net.node_id[i]},
                                    {"type", to_string(b.type)},
                                    {"flow", (*inflow)[i]},
                                    {"pressure", (*pressure)[i]}};
            if (!b.is_outlet()) entry["hematocrit"] = b.entering_hematocrit(blood);
            return entry;
          }};
}

VesselTable steady_results(const Network& net, const CycleSummary& cycle) {
  const std::size_t n = net.vessel_count();
  VesselTable table = cycle_table(net, cycle, std::vector<std::uint8_t>(n, 0), {"steady"},
                                  std::vector<std::int64_t>(n, VesselTable::null_integer));
  for (const char* name : {"womersley", "pwv_elastic", "pwv_theory"})
    table.add_number(name, std::vector<double>(n, std::numeric_limits<double>::quiet_NaN()));
  return table;
}

void run_steady(const Network& net, const SteadyRunRequest& request, RunObserver& observer) {
  auto blood_of = [&](const Network& n) {
    Blood b = n.blood.value_or(Blood{});
    if (request.rheology_override >= 0) b.rheology = static_cast<Rheology>(request.rheology_override);
    return b;
  };
  const Blood blood = blood_of(net);
  // Over MPI ranks (distributed/steady_over_ranks.hpp) rank 0 alone takes the folder and
  // writes; its refusal is every rank's before any of them enters the solve.
  std::optional<OutputFolder> taken;
  on_lead_rank([&] { taken.emplace(request.out_dir); });
  const auto started = std::chrono::steady_clock::now();
  SteadyFlow steady;
  SteadyHematocritResult separated;
  // Over ranks of an HDF5 network each rank but the lead holds its slice alone where slices
  // serve it (distributed/steady_on_slices.hpp); a network they do not serve is read whole on
  // every rank.
  Network whole;
  auto whole_here = [&]() -> const Network& {
    if (request.network_in_slices)
      on_every_rank([&] {
        if (world_rank() != 0) whole = read_network(request.input);
      });
    return request.network_in_slices && world_rank() != 0 ? whole : net;
  };
  if (world_size() > 1 && request.phase_separation) {
    // Each pass's flows over the ranks, the hematocrits on rank 0 (as below, relaxed by half).
    std::optional<SteadyHematocritOverRanks> over;
    if (request.network_in_slices)
      over = solve_steady_with_phase_separation_on_slices(net, request.input, blood_of, red_cell_iterations,
                                                          red_cell_tolerance, 0.5);
    if (!over) {
      const Network& own = whole_here();
      over = solve_steady_with_phase_separation_over_ranks(own, blood_of(own), red_cell_iterations, red_cell_tolerance, 0.5);
    }
    if (world_rank() != 0) return;
    leave_collectives();
    observer.note(over->partition);
    separated = std::move(over->result);
    steady = separated.flow;
  } else if (world_size() > 1) {
    std::optional<SteadyOverRanks> over;
    if (request.network_in_slices)
      if (SteadyFlowOnSlices slices(net, request.input, blood_of); slices.serves()) over = slices.solve();
    if (!over) {
      const Network& own = whole_here();
      over = solve_steady_flow_over_ranks(own, blood_of(own), own.inlet ? own.inlet->waveform.mean_value() : 0.0);
    }
    if (world_rank() != 0) return;
    leave_collectives();  // the others have finished: a failure of the writing is rank 0's alone
    observer.note(over->partition);
    steady = std::move(over->flow);
  } else if (request.phase_separation) {
    // Under-relaxed by half: undamped, the rat mesentery's split oscillates (Gardner et al.
    // 2010 on such networks); 59 passes to 1e-10 there.
    separated = solve_steady_with_phase_separation(net, blood, red_cell_iterations, red_cell_tolerance, 0.5);
    steady = separated.flow;
  } else {
    steady = solve_steady_flow(net, vessel_resistances(net, blood, {}, request.threads),
                               net.inlet ? net.inlet->waveform.mean_value() : 0.0);
  }
  const CycleSummary cycle = steady_cycle(net, blood, steady, request.phase_separation ? &separated.hematocrit : nullptr);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  VesselTable results = steady_results(net, cycle);
  if (request.phase_separation) {
    std::vector<double> tube(net.vessel_count());
    for (std::size_t v = 0; v < tube.size(); ++v)
      tube[v] = tube_hematocrit(separated.hematocrit[v], net.diameter[v], blood.pries_diameter_scale());
    results.add_number("discharge_hematocrit", separated.hematocrit);
    results.add_number("tube_hematocrit", std::move(tube));
  }
  nlohmann::json run_info = {{"tool", "hemosolve"},
                             {"version", HEMOTREE_VERSION},
                             {"network", request.input},
                             {"mode", "steady"},
                             {"model", "steady"},
                             {"vessels_1d", 0},
                             {"vessels_0d", 0},
                             {"rheology", to_string(blood.rheology)},
                             {"mean_cell_volume", blood.mean_cell_volume},
                             {"red_cells", request.phase_separation ? "phase_separation" : "fixed"},
                             {"status", !request.phase_separation || separated.converged ? "complete" : "not converged"},
                             {"cycles", 0},
                             {"wall_time", wall}};
  if (request.phase_separation)
    run_info["red_cell_iterations"] = {{"passes", separated.iterations},
                                       {"change", separated.change},
                                       {"tolerance", red_cell_tolerance},
                                       {"relaxation", 0.5}};
  run_info["statistics"] = group_statistics(net, results, request.threads);
  OutputFolder& folder = *taken;
  folder.open();
  const std::filesystem::path dir = folder.staging();
  write_results(dir, {run_info, results, cycle, boundary_results(net, steady), nullptr, request.threads},
                request.results_format);
  if (request.vtk) write_results_vtk(dir / "results.vtp", net, results, request.vtk_keep);
  folder.publish();
  if (request.phase_separation && !separated.converged)
    throw InputError("the flows and hematocrits did not converge in " + std::to_string(separated.iterations) +
                     " passes (last change " + format_rounded(separated.change) +
                     "): phase separation may have no steady state here, or several; " +
                     request.out_dir.string() + " holds the last pass, marked \"not converged\"");
  observer.note("steady state of " + std::to_string(net.vessel_count()) + " vessels in " + format_quantity(wall, "s") +
         ": " + format_quantity(cycle.inlet_mean_flow, "nl/min") + " in through the boundaries; results in " +
         request.out_dir.string());
}

}  // namespace hemotree
