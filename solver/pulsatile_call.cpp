#include "solver/pulsatile_call.hpp"

#include "solver/results_files.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include "core/free_memory.hpp"
#include "core/units.hpp"
#include "core/errors.hpp"
#include "core/setting_error.hpp"
#include "formats/checkpoint_file.hpp"
#include "mpi/session.hpp"
#include "pulse/pulse_solver.hpp"
#include "solver/flow_transport.hpp"
#include "solver/decisions_over_ranks.hpp"
#include "solver/output_folder.hpp"
#include "solver/pulse_ranks_mpi.hpp"
#include "solver/pulsatile_run.hpp"
#include "solver/run_estimate.hpp"
#include "solver/run_identity.hpp"
#include "solver/run_report.hpp"
#include "solver/steady_run.hpp"
#include "solver/transport_report.hpp"

namespace hemotree {

namespace {

constexpr double one_day = 86400;
// The scheme's own mass balance: round-off plus the junctions' Newton tolerance (1e-12 of
// the flow; docs/solver.md). Far above both and far below any error that changes a result.
constexpr double conservation_tolerance = 1e-8;
// Steady or mean pressures outside this band are not physiological [mmHg].
constexpr double physiological_low = 0, physiological_high = 300;

std::string plural(std::size_t count, const std::string& noun) {
  return std::to_string(count) + " " + noun + (count == 1 ? "" : "s");
}

// Warns when pressures leave the physiological band, with the likely cause.
void warn_unphysiological(double low, double high, std::int64_t vessel, const Network& net, const char* what,
                          const SettingWords& words, RunObserver& observer) {
  if (!std::isfinite(low) || !std::isfinite(high)) return;
  if (low >= physiological_low * pascal_per_mmhg && high <= physiological_high * pascal_per_mmhg) return;
  observer.warn(std::string(what) + " reach " + format_quantity(high, "mmHg") + " (lowest " +
                format_quantity(low, "mmHg") + ", at vessel " + std::to_string(vessel) +
                "), outside a physiological 0 to 300 mmHg: " +
                (net.inlet ? "the inlet's mean flow (" + format_quantity(net.inlet->waveform.mean_value(), "ml/min") +
                                 ") is likely wrong for this network's size (vprune " +
                                 in_words(placeholder("mean_flow"), words) + " sets it)"
                           : std::string("the boundary flows and pressures are likely wrong for this network")));
}

// The checkpoint a resume continues from (null without one), checked whole before the run is
// set up, and read from its file as the run asks (over ranks every rank opens and checks it
// too, from the path rank 0 found, which every rank must see, as it sees the network's: none
// holds its bytes). A killed run's checkpoint is not overwritten by a fresh run unless forced.
std::unique_ptr<CheckpointReader> checkpoint_to_resume(const OutputFolder& folder, const RunConfiguration& config) {
  std::unique_ptr<CheckpointReader> checkpoint;
  if (config.resume) {
    const auto file = folder.latest_checkpoint();
    if (!file)
      throw SettingError("resume", placeholder("resume") + " " + config.out_dir + ": no checkpoint.bin in it or in " +
                                       folder.staging().string() + " (a run writes one when interrupted, or every N "
                                       "cycles with " + placeholder("checkpoint_every") + " N)");
    checkpoint = std::make_unique<CheckpointReader>(*file);
  }
  if (!config.resume && !config.force && folder.latest_checkpoint() &&
      folder.latest_checkpoint()->parent_path() == folder.staging())
    throw SettingError("force", folder.staging().string() + " holds the checkpoint of a run that was killed: " +
                                    placeholder("resume") + " " + config.out_dir + " continues it; " +
                                    placeholder("force") + " (or removing that folder) starts afresh");
  return checkpoint;
}

// The discretisation's size and cost, said before the run and refused above a day a cycle.
struct Discretisation {
  TimeStepDecision step;
  std::map<int, std::size_t> degrees;  // elements per degree
  std::size_t one_d = 0;
};

Discretisation decide_discretisation(const Network& net, PulseSolver& run, const RunConfiguration& config,
                                     double period, RunObserver& observer) {
  Discretisation d;
  d.step = decide_time_step(run, config, period);
  const std::size_t steps_per_cycle = d.step.cycle.steps_per_cycle;
  const double dt = d.step.cycle.dt;
  if (static_cast<std::size_t>(config.frames) > steps_per_cycle)
    throw SettingError("frames", placeholder("frames") + " " + std::to_string(config.frames) + " exceeds the " +
                                     std::to_string(steps_per_cycle) + " steps of a cycle");
  for (std::size_t v = 0; v < net.vessel_count(); ++v)
    if (!run.is_lumped(v)) d.degrees[run.degree(v)] += static_cast<std::size_t>(config.solver.elements);
  std::vector<double> elements_of_degree(static_cast<std::size_t>(run.max_degree()) + 1, 0.0);
  std::string degree_list;
  for (const auto& [p, count] : d.degrees) {
    elements_of_degree[static_cast<std::size_t>(p)] = static_cast<double>(count);
    degree_list += (degree_list.empty() ? "" : ", ") + std::to_string(count) + " of degree " + std::to_string(p);
  }
  const int planned = config.planned_cycles(), threads = config.solver.threads;
  // Over P ranks each steps about a P-th of the 0D vessels; the 1D vessels are the top's, or,
  // spread over the ranks, each rank's own: the rank with the costliest substep sets the pace.
  const int ranks = world_size();
  if (run.one_d_spread()) {
    const std::span<const std::int32_t> rank_of = run.vessel_ranks();
    std::vector<std::vector<double>> of_rank(static_cast<std::size_t>(ranks), std::vector<double>(elements_of_degree.size(), 0.0));
    for (std::size_t v = 0; v < net.vessel_count(); ++v)
      if (!run.is_lumped(v))
        of_rank[static_cast<std::size_t>(rank_of[v])][static_cast<std::size_t>(run.degree(v))] += config.solver.elements;
    double costliest = -1;
    for (const std::vector<double>& elements : of_rank)
      if (const double cost = estimate_run(elements, 1.0, 1, 1.0, 0.0).seconds; cost > costliest) {
        costliest = cost;
        elements_of_degree = elements;
      }
  }
  const double lumped = static_cast<double>(run.lumped_vessels_in_run()) / ranks, substeps = run.substeps() * run.coupling_passes();
  // A 0D system spread over the ranks: its solves a step, over a rank's nodes.
  const LumpedVessels& zero_d = run.lumped();
  const double spread_solves = zero_d.halo() ? 1.0 + static_cast<double>(zero_d.halo_couplings()) : 0.0;
  const double spread_nodes = static_cast<double>(zero_d.node_count());
  RunEstimate per_cycle = estimate_run(elements_of_degree, static_cast<double>(steps_per_cycle), threads, substeps, lumped,
                                       spread_solves, spread_nodes);
  RunEstimate whole = estimate_run(elements_of_degree, static_cast<double>(steps_per_cycle) * planned, threads, substeps,
                                   lumped, spread_solves, spread_nodes);
  if (config.carries_transport()) {
    // Its cells: a node's of the 0D vessels (about one a vessel), the 1D elements' slices (a
    // degree's modes each); a rank carries its own. Its steps: as the run takes them below.
    const double cells = (static_cast<double>(run.lumped_vessels_in_run()) +
                          static_cast<double>(run.element_count()) * (run.max_degree() + 1)) / ranks;
    const auto every = std::max<std::size_t>(
        1, static_cast<std::size_t>(std::llround(config.transport_step * static_cast<double>(steps_per_cycle))));
    const double transport = cells * static_cast<double>(steps_per_cycle / every) * per_transport_cell;
    per_cycle.seconds += transport;
    whole.seconds += transport * planned;
  }
  if (per_cycle.seconds > one_day && !config.force)
    throw SettingError("force", "one cycle would take about " + describe_duration(per_cycle.seconds) + " (" +
                     format_rounded(static_cast<double>(steps_per_cycle)) + " steps of " + format_quantity(dt, "s") +
                     (d.step.reason.starts_with("given") ? ", " : ", set by the ") + d.step.reason + "; " + plural(run.element_count(), "element") +
                     "): refused, more than a day. Check that vessel's wall and length and the inlet's "
                     "flow, use fewer " + placeholder("elements") + " or a lower " + placeholder("degree") + ", or " +
                     placeholder("force") + " to run it anyway");
  d.one_d = net.vessel_count() - run.lumped_vessels_in_run();
  const std::size_t sectioned = run.sectioned_count();
  observer.note(plural(d.one_d, "vessel") + " 1D, " + std::to_string(run.lumped_vessels_in_run()) + " 0D (" +
                in_words(placeholder("model"), config.words) + " " + to_string(config.solver.model) +
                (sectioned > 0 ? ", " + std::to_string(sectioned) + " of them in pi sections" : std::string()) + ")" +
                (run.lumped_vessels_in_run() > 0 && d.one_d > 0
                     ? "; " + std::to_string(run.substeps()) + " 1D substeps of " +
                           format_quantity(run.substep(), "s") + " per step" +
                           (run.coupling_passes() > 1 ? ", taken " + std::to_string(run.coupling_passes()) + " times"
                                                      : std::string())
                     : std::string()));
  observer.note("time step " + format_quantity(dt, "s") + " (" + d.step.reason + "), " +
                std::to_string(steps_per_cycle) + " steps per cycle, " + plural(run.element_count(), "element") +
                (degree_list.empty() ? "" : ": ") + degree_list + "; estimated " +
                describe_duration(per_cycle.seconds) + " per cycle, " + describe_duration(whole.seconds) +
                (config.until_periodic ? " for at most " : " for ") + plural(planned, "cycle") + " on " +
                (ranks > 1 ? std::to_string(ranks) + " ranks of " : std::string()) + plural(threads, "thread"));
  if (whole.seconds > one_day && observer.hears_notes())
    observer.warn("the whole run may take " + describe_duration(whole.seconds) + " (use " +
                  in_words(placeholder("checkpoint_every"), config.words) + " N to be able to resume it)");
  return d;
}

// A run is complete only when its numbers say so: the reason it is not, or empty.
std::string check_results(const Network& net, const PulseSolver& run, const PulsatileRun& pulsatile,
                          RunStatus status, const std::string& beyond_limit) {
  if (status != RunStatus::complete && status != RunStatus::not_periodic) return {};
  // A forced step beyond the limit runs, for whoever wants to see what it gives, but its
  // numbers are outside the scheme's accuracy: never complete.
  if (!beyond_limit.empty()) return beyond_limit + ", forced: the results are outside the scheme's accuracy";
  const CycleSummary& last = pulsatile.last_cycle();
  if (!(std::abs(last.conservation_error) < conservation_tolerance))
    return "the scheme lost mass: (in - out - stored) / in = " + format_rounded(last.conservation_error) +
           " over the last cycle, above " + format_rounded(conservation_tolerance);
  // Each prescribed flow's mean against what went through it (a zero mean within 1e-6 of the flow in).
  const RunBoundaries& list = run.boundary_list();
  for (std::size_t i = 0; i < list.size() && i < last.boundary_mean_flow.size(); ++i) {
    if (list.type(i) != BoundaryType::flow) continue;
    const double prescribed = list.waveform(i).mean_value(), got = last.boundary_mean_flow[i];
    if (std::abs(got - prescribed) <= 1e-2 * std::abs(prescribed) + 1e-6 * std::abs(last.inlet_mean_flow)) continue;
    const bool inlet = net.inlet && net.boundaries.empty();
    return (inlet ? std::string("the inlet's mean flow")
                  : "the mean flow into node " + std::to_string(net.node_id[static_cast<std::size_t>(list.node(i))])) +
           " over the last cycle is " + format_quantity(got, "ml/min") + " where the waveform prescribes " +
           format_quantity(prescribed, "ml/min") + ": the time step cannot follow the pulse";
  }
  return {};
}

RunOutcome outcome_of(RunStatus status, const std::string& failure) {
  return !failure.empty()                     ? RunOutcome::failed
         : status == RunStatus::broken_down  ? RunOutcome::broken_down
         : status == RunStatus::interrupted  ? RunOutcome::interrupted
         : status == RunStatus::not_periodic ? RunOutcome::not_periodic
                                             : RunOutcome::complete;
}

// summary.json's "run": the configuration as run, the step and what came of it.
nlohmann::json run_info(const Network& net, const PulseSolver& run, const RunConfiguration& config,
                        const Discretisation& d, const PulsatileRun& pulsatile, RunOutcome outcome, double wall) {
  const SolverOptions& options = config.solver;
  const bool steady_start = run.started_from_steady();
  const Waveform driving = driving_waveform(net);
  const std::size_t steps_per_cycle = d.step.cycle.steps_per_cycle;
  nlohmann::json info = {{"tool", "hemosolve"}, {"version", HEMOTREE_VERSION},
                         {"network", config.network_name},
                         {"degree", options.degree == SolverOptions::automatic ? nlohmann::json("auto")
                                                                               : nlohmann::json(options.degree)},
                         {"elements_per_vessel", options.elements}, {"scheme", to_string(options.scheme)},
                         {"model", to_string(options.model)},
                         {"vessels_1d", d.one_d},
                         {"vessels_0d", run.lumped_vessels_in_run()},
                         {"vessels_0d_in_sections", run.sectioned_count()},
                         {"substeps", run.substeps()},
                         {"coupling_passes", run.coupling_passes()},
                         {"threads", options.threads},
                         {"rheology", to_string(run.blood().rheology)},
                         {"red_cells", to_string(config.red_cells)},
                         {"mean_cell_volume", run.blood().mean_cell_volume},
                         {"start", to_string(run.started_from())},
                         {"start_requested", to_string(options.start)},
                         {"balance_compliances", config.balance_compliances && steady_start},
                         {"period", driving.period},
                         {"pulse_frequency", pulse_frequency(driving)},
                         {"analysis_frequency", analysis_frequency(driving)},
                         {"time_step", d.step.cycle.dt}, {"time_step_limit", d.step.reason},
                         {"steps_per_cycle", steps_per_cycle},
                         {"status", to_string(outcome)},
                         {"cycles", pulsatile.cycles_done()},
                         {"steps", static_cast<std::uint64_t>(pulsatile.cycles_done()) * steps_per_cycle},
                         {"compliance_balances", pulsatile.compliance_balances()},
                         {"wall_time", wall}};
  if (pulsatile.settling().steps > 0)
    info["settling_cycle"] = {{"steps", pulsatile.settling().steps}, {"seconds", pulsatile.settling().seconds}};
  if (pulsatile.settling().degree > 0) info["settling_cycle"]["degree"] = pulsatile.settling().degree;
  if (!steady_start && options.start != StartChoice::rest) info["steady_refusal"] = run.steady_refusal();
  if (!run.periodic_refusal().empty()) info["periodic_refusal"] = run.periodic_refusal();
  for (const auto& [p, count] : d.degrees) info["elements_of_degree"][std::to_string(p)] = count;
  if (pulsatile.has_change()) {
    info["periodic_change"] = pulsatile.change().change;
    info["slowest_vessel"] = net.id[pulsatile.change().vessel];
  }
  return info;
}

// Each boundary's mean flow into the network over the last cycle (as the steady run reports).
SummaryArray boundary_flows(const Network& net, const PulseSolver& run, const CycleSummary& last) {
  if (last.boundary_mean_flow.empty()) return {};
  return {"boundaries", run.boundary_list().size(), [&net, &run, &last](std::size_t i) {
            const NodeBoundary b = run.boundary_list()[i];
            nlohmann::json entry = {{"node", net.node_id[static_cast<std::size_t>(b.node)]},
                                    {"type", to_string(b.type)},
                                    {"flow", last.boundary_mean_flow[i]}};
            if (!b.is_outlet()) entry["hematocrit"] = b.entering_hematocrit(run.blood());
            return entry;
          }};
}

// The notes and warnings of a run that ended with its numbers: its length, the red cells'
// unrest, unphysiological pressures, a tracer the run never reached.
void say_results(const Network& net, const PulseSolver& run, const RunConfiguration& config,
                 const PulsatileRun& pulsatile, const FlowTransport::Outcome* transport, double wall, RunObserver& observer) {
  std::ostringstream m;
  m << plural(pulsatile.cycles_done(), "cycle") << " in " << describe_duration(wall);
  if (pulsatile.has_change())
    m << "; last cycle-to-cycle change " << format_rounded(pulsatile.change().change) << " (vessel "
      << net.id[pulsatile.change().vessel] << ")";
  m << "; results in " << config.out_dir;
  observer.note(m.str());
  // The red cells' own unrest, said plainly: a network can oscillate by itself (docs/transport.md).
  const RedCellCycle& cells = pulsatile.last_red_cells();
  if (transport && transport->red_cells && !cells.discharge.empty())
    observer.note(red_cell_line(net, cells, pulsatile.red_cell_change()));
  const CycleSummary& last = pulsatile.last_cycle();
  double low = INFINITY, high = -INFINITY;
  std::size_t highest = 0;
  for (std::size_t v = 0; v < last.vessels.size(); ++v) {
    low = std::min(low, last.vessels[v].mean_pressure);
    if (last.vessels[v].mean_pressure > high) high = last.vessels[(highest = v)].mean_pressure;
  }
  warn_unphysiological(low, high, net.id[highest], net, "mean pressures", config.words, observer);
  // A tracer whose injection the run never reached has no curves: said, not left to be found.
  for (std::size_t k = 0; transport && k < config.tracers.size(); ++k)
    if (const FlowTransport::TracerReport& moved = transport->reports[k]; moved.entered + moved.injected == 0)
      observer.warn("tracer " + config.tracers[k].name + " never entered the network (its injection starts at t = " +
                    format_quantity(config.tracers[k].start, "s") + ", the run ended at t = " +
                    format_quantity(run.time(), "s") + "): its arrival, peak and transit times are null");
}

}  // namespace

void check_pulsatile(const Network& net, const RunConfiguration& config) {
  if (!net.inlet && net.boundaries.empty())
    throw InputError("the network has no \"inlet\": hemosolve needs one (vprune adds it), or \"boundaries\"");
  // The common period of the time-varying boundary conditions (1 s where all are constant).
  const double period = driving_waveform(net).period;
  if (!Interval{0, period, true, false}.contains(config.sample_interval))
    throw SettingError("sample_interval", placeholder("sample_interval") + " must lie in " +
                                              describe({0, period, true, false}, "s") + " (got " +
                                              format_quantity(config.sample_interval, "s") + ")");
}

namespace {

// given_up: the same network where the caller gave it up (its coordinates may go), else null.
RunResult pulsatile(const Network& net, const RunConfiguration& given, RunObserver& observer, Network* given_up) {
  // Over MPI ranks (mpirun -np P, P > 1) the tree's 0D vessels are cut into whole subtrees,
  // the 1D vessels and every vessel above them on the top's rank, rank 0, or, where the 1D
  // vessels cost more than a rank's share or the network has loops, the 1D vessels are spread
  // over the ranks (solver/pulse_ranks_mpi.hpp); every decision is agreed (solver/decisions_over_ranks.hpp)
  // and rank 0 alone writes. One pi section a 0D vessel: a cut runs between vessels
  // (pulse/lumped_cut.hpp); the run is then, and its checkpoint says so, the one-process run
  // with --lumped-sections 1.
  const bool over_ranks = world_size() > 1;
  RunConfiguration config = given;
  if (over_ranks) config.solver.lumped_sections = 1;
  on_every_rank([&] {
    check_configuration(config);
    check_pulsatile(net, config);
  });
  // The network's identity (its coordinates included) before anything of it is freed.
  const std::uint64_t network = network_identity(net);
  if (given_up && !config.vtk && config.frames == 0)
    for (std::vector<double>* c : {&given_up->x, &given_up->y, &given_up->z}) std::vector<double>().swap(*c);
  const Waveform driving = driving_waveform(net);
  const double period = driving.period;
  std::optional<OutputFolder> folder;  // rank 0's (over ranks its refusal is every rank's)
  std::unique_ptr<CheckpointReader> checkpoint;
  on_lead_rank([&] {
    folder.emplace(config.out_dir);
    checkpoint = checkpoint_to_resume(*folder, config);
  });
  std::string resumed_from = checkpoint ? checkpoint->source() : std::string();
  // Over ranks every rank resumes from rank 0's checkpoint, and knows its folder (no rank but
  // 0 writes there).
  std::string staging = folder ? folder->staging().string() : std::string();
  if (over_ranks) {
    take_lead_text(staging);
    take_lead_text(resumed_from);
    // Each rank's own reader, its refusal every rank's (in a step of its own: once the
    // resume has begun, a rank may be in a collective call with the others).
    if (!resumed_from.empty())
      on_every_rank([&] {
        if (!checkpoint) checkpoint = std::make_unique<CheckpointReader>(resumed_from);
      });
  }
  RunResult result;
  // Interrupted where no cycle has ended (before the time loop, or in a settling cycle):
  // nothing is written, the run just stops.
  auto stopped_unstarted = [&](int signal, const std::string& where) {
    result.signal = signal;
    observer.warn("interrupted by " + observer.signal_name(signal) + " " + where + ": nothing written");
    result.outcome = RunOutcome::interrupted;
    result.started = false;
  };
  auto interrupted_before_start = [&] {
    const int signal = over_ranks ? interrupt_on_any_rank(observer.poll_interrupt()) : observer.poll_interrupt();
    if (signal != 0) stopped_unstarted(signal, "before the first step");
    return signal != 0;
  };
  if (interrupted_before_start()) return result;

  // ---- the discretisation, its step and its cost ---------------------------------------
  SolverOptions options = solver_options(config);
  std::optional<MpiPulseRanks> ranks;
  if (over_ranks) {
    // A tree's subtrees; its 1D vessels spread where that balances the step. With red cells or
    // tracers, the top wherever there can be one: their step crosses a top's cut in two
    // messages, a spread cut in rounds (solver/flow_transport_spread.cpp).
    const OneDLayout layout = config.carries_transport() ? OneDLayout::top_where_possible : OneDLayout::balanced;
    on_every_rank([&] { ranks.emplace(net, std::vector<double>(net.vessel_count(), 1.0), layout); });
    if (given.solver.lumped_sections > 1)
      observer.note("over " + std::to_string(world_size()) + " MPI ranks every 0D vessel is one pi section (" +
                    in_words(placeholder("lumped_sections"), config.words) + " 1): a vessel that would need more is 1D");
  }
  // The steady solve: minutes on the full tree. Over ranks a refusal of the cut (a rank left
  // without a vessel) is every rank's alike.
  std::optional<PulseSolver> solver;
  on_every_rank([&] { solver.emplace(net, options, ranks ? &ranks->ranks() : nullptr); });
  PulseSolver& run = *solver;
  if (ranks && ranks->zero_d_spread())
    observer.note(describe(ranks->partition()) + ", weighed by each vessel's step; the 0D vessels spread over the ranks, "
                  "each rank with a halo of the others' at its nodes, every step solved over the ranks by PETSc (" +
                  ranks->zero_d_solves().method + "): the plain command's numbers to about 1e-8, not bit for bit");
  else if (ranks && ranks->one_d_spread())
    observer.note(describe(ranks->partition()) + ", weighed by each vessel's step; the 1D vessels spread over the ranks "
                  "(the 0D vessels meeting at a node on one rank), their traces exchanged at the cut's junctions and "
                  "their couplings to 0D nodes across it");
  else if (ranks)
    observer.note(describe(ranks->partition()) + "; the top's rank steps " + std::to_string(ranks->top_vessels()) +
                  " vessels (the 1D ones and every vessel above them, with subtrees of its own; weighed for its "
                  "statistics as " + std::to_string(std::llround(ranks->top_weight())) + " vessels more)");
  // The settling cycle at a lower 1D degree (solver/settling_cycle.hpp) takes a solver of its
  // own, built here while the network still has its walls (over ranks on the run's cut).
  std::unique_ptr<PulseSolver> settling;
  if (resumed_from.empty())
    on_every_rank([&] { settling = low_degree_settling_solver(net, run, config, period, ranks ? &ranks->ranks() : nullptr); });
  if (ranks) ranks->end_dealing();
  // The walls are in the vessels' tube laws now; only a VTK file would write them again.
  if (given_up && !config.vtk && config.frames == 0)
    for (std::vector<double>* wall : {&given_up->wall_thickness, &given_up->youngs_modulus}) std::vector<double>().swap(*wall);
  if (interrupted_before_start()) return result;
  Discretisation d;  // its refusal (a cycle above a day, too many frames) every rank's alike
  on_every_rank([&] { d = decide_discretisation(net, run, config, period, observer); });
  const std::size_t steps_per_cycle = d.step.cycle.steps_per_cycle;
  const double dt = d.step.cycle.dt;

  // ---- what the run starts from, said as it is --------------------------------------------
  if (config.solver.start != StartChoice::rest && !run.started_from_steady())
    observer.warn("no steady solution to start from (" + run.steady_refusal() + "): starting from rest" +
                  (config.balance_compliances ? std::string(", without the compliance balance (it needs the steady network)")
                                              : std::string()));
  if (!run.periodic_refusal().empty())
    observer.warn("no linear periodic state to start from (" + run.periodic_refusal() + "): starting from the steady state");
  warn_unphysiological(run.steady_pressure_min(), run.steady_pressure_max(), net.id[run.steady_pressure_max_vessel()],
                       net, "steady pressures", config.words, observer);

  // ---- the run ------------------------------------------------------------------------------
  const RunIdentity identity{network, state_shaping(config, net, dt, run.blood().rheology)};
  RunPlan plan;
  plan.cycles = config.cycles;
  plan.until_periodic = config.until_periodic;
  plan.periodic_tolerance = config.periodic_tolerance;
  plan.max_cycles = config.max_cycles;
  plan.balance_compliances = config.balance_compliances;
  plan.frames = config.frames;
  plan.vtk_keep = config.vtk_keep;
  plan.steps_per_cycle = steps_per_cycle;
  plan.sample_every = std::max<std::size_t>(1, static_cast<std::size_t>(std::llround(config.sample_interval / dt)));
  plan.checkpoint_every = config.checkpoint_every;
  plan.network_identity = identity.network;
  plan.state_shaping = identity.shaping;
  plan.longest_cycle = config.force ? 0 : one_day;
  // The settling cycle, where the run seeks the periodic state and its 0D vessels can take a
  // longer step (solver/settling_cycle.hpp): as many of its steps as fill a period. Only where
  // most of the vessels are 0D: the transient it takes cheaply is theirs, and where 1D arteries
  // are the network with a few short 0D segments between them (ADAN56), a longer 0D step saves
  // nothing and broke down (the segments' nodes, tiny compliances between two 1D ends).
  if (config.until_periodic && config.settling_step > 1 && 2 * run.lumped_vessels_in_run() > net.vessel_count() &&
      config.balance_compliances && run.started_from_steady())
    plan.settling_steps = std::max<std::size_t>(
        1, steps_per_cycle * static_cast<std::size_t>(run.coupling_passes()) / static_cast<std::size_t>(config.settling_step));
  if (settling) plan.settling_steps = low_degree_settling_steps(*settling, period, config.settling_step);
  std::optional<FlowTransport> transport;
  if (config.carries_transport()) {
    const bool red = config.red_cells == RedCells::transport;
    const std::vector<TracerSpec>& tracers = config.tracers;
    FlowTransportOptions carried;
    carried.tracers = tracers;
    std::optional<TransportRanks> over;
    if (ranks) over = TransportRanks{ranks->ranks().top_rank, ranks->roots()};
    // A refusal (a tracer given where the network has no boundary) is every rank's alike.
    on_every_rank([&] { transport.emplace(net, run, red ? carried : red_cells_fixed(carried), over ? &*over : nullptr); });
    if (over) transport->join_ranks();
    plan.transport_every = std::max<std::size_t>(
        1, static_cast<std::size_t>(std::llround(config.transport_step * static_cast<double>(steps_per_cycle))));
    observer.note(std::string(red ? "red cells" : "") + (red && !tracers.empty() ? " and " : "") +
                  (tracers.empty() ? "" : plural(tracers.size(), "tracer")) + " carried on " +
                  plural(transport->cell_count(), "cell") + " (" + describe_bytes(static_cast<double>(transport->bytes())) +
                  (over ? " on rank 0)" : ")") + ", a transport step every " +
                  plural(plan.transport_every, "flow step"));
  }
  PulsatileRun pulsatile(net, run, config.probes, plan, staging, transport ? &*transport : nullptr);
  if (settling) pulsatile.settle_with(std::move(settling));
  if (!resumed_from.empty()) {
    // Its refusal (another run's, one at the run's end) is every rank's alike.
    on_every_rank([&] { pulsatile.resume(std::move(checkpoint)); });
    observer.note("resuming from " + resumed_from + " after " + std::to_string(pulsatile.cycles_done()) +
                  " cycles (t = " + format_quantity(run.time(), "s") + ")");
  }
  on_lead_rank([&] {
    // A resume at the run's end keeps the killed run's last frames; a resume of a killed run
    // its checkpoint, as the run's first snapshot.
    folder->open(pulsatile.keeps_frames(), pulsatile.resumed_snapshot_name());
    if (config.frames > 0) {
      std::error_code ec;
      std::filesystem::create_directories(folder->staging() / "frames", ec);
      if (ec) throw IoError("cannot create " + (folder->staging() / "frames").string() + ": " + ec.message());
    }
  });
  const auto started = std::chrono::steady_clock::now();
  const RunStatus status = pulsatile.run(observer);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  if (over_ranks) {
    // The run's end is every rank's; the results (and what comes of them) are rank 0's,
    // which has left every collective call: a failure of its writing is its own alone.
    if (world_rank() != 0) return result;
    leave_collectives();
    if (ranks->zero_d_spread()) {
      const MpiPulseRanks::ZeroDSolves s = ranks->zero_d_solves();
      observer.note("the 0D steps' solves on rank 0: " + std::to_string(s.solves) + " solves, " +
                    std::to_string(s.iterations) + " iterations, " + std::to_string(s.setups) +
                    " preconditioner set-ups, " + format_quantity(s.seconds, "s") + " inside them");
    }
    if (ranks->one_d_spread()) {
      const MpiPulseRanks::SpreadTraffic& t = ranks->spread_traffic();
      observer.note("the 1D vessels' exchanges on rank 0: " + std::to_string(t.messages) + " messages to its neighbouring ranks, " +
                    std::to_string(t.bytes) + " bytes (traces, coupled ends), " + std::to_string(t.reductions) +
                    " reductions, " + format_quantity(t.seconds, "s") + " inside them (waiting for the neighbours included)");
    }
    if (const RootExchange* exchange = ranks->exchange()) {
      const RootExchange::Traffic& t = exchange->traffic();
      observer.note("the 0D steps' exchanges on rank 0, the top's: " + std::to_string(t.calls) + " collective calls, " +
                    std::to_string(t.bytes) + " bytes, " + format_quantity(t.seconds, "s") +
                    " inside them (waiting for the shares included)");
    }
    if (const FlowTransport::SpreadTraffic* t = transport ? transport->spread_traffic() : nullptr)
      observer.note("the transport's exchanges on rank 0: " + std::to_string(t->rounds) + " rounds in " +
                    std::to_string(t->steps) + " steps, " + std::to_string(t->messages) + " messages to its neighbouring ranks, " +
                    std::to_string(t->bytes) + " bytes, " + format_quantity(t->seconds, "s") + " inside them");
    if (const RootExchange* exchange = transport ? transport->exchange() : nullptr) {
      const RootExchange::Traffic& t = exchange->traffic();
 observer.note("the transport steps' exchanges on rank 0: " + std::to_string(t.calls) + " collective calls, " +
                    std::to_string(t.bytes) + " bytes, " + format_quantity(t.seconds, "s") + " inside them");
    }
  }
  if (pulsatile.stopped_settling()) {
    folder->discard();
    stopped_unstarted(pulsatile.signal(), "in the settling cycle");
    return result;
  }
  const CycleSummary& last = pulsatile.last_cycle();

  const std::string failure = check_results(net, run, pulsatile, status, d.step.beyond_limit);
  result.outcome = outcome_of(status, failure);
  result.signal = pulsatile.signal();
  nlohmann::json info = run_info(net, run, config, d, pulsatile, result.outcome, wall);
  if (!failure.empty()) info["error"] = failure;
  if (status == RunStatus::broken_down) info["error"] = in_words(pulsatile.breakdown(), config.words);
  if (status == RunStatus::interrupted)
    info["error"] = "interrupted by " + observer.signal_name(pulsatile.signal()) + "; resume with " +
                    in_words(placeholder("resume"), config.words) + " " + config.out_dir;

  if (status == RunStatus::too_long) {
    folder->discard();
    const double cycle = pulsatile.measured_step() * static_cast<double>(steps_per_cycle);
    throw SettingError("force", "one cycle would take about " + describe_duration(cycle) + " (measured over its first steps: " +
                     format_quantity(pulsatile.measured_step(), "s") + " a step, " +
                     format_rounded(static_cast<double>(steps_per_cycle)) +
                     " steps): stopped, more than a day. Use fewer " + placeholder("elements") + " or a lower " +
                     placeholder("degree") + ", " + placeholder("threads") + ", or " + placeholder("force") +
                     " to run it anyway");
  }
  // Nothing computed, nothing kept: DIR stays as it was.
  if (status == RunStatus::broken_down && last.vessels.empty()) {
    folder->discard();
    throw_input_error(pulsatile.breakdown());  // its placeholders worded by the catcher
  }
  const std::filesystem::path dir = folder->staging();
  if (status == RunStatus::interrupted || config.checkpoint_every > 0) pulsatile.write_checkpoint();
  pulsatile.discard_snapshot();
  // The transport is spent: what the results read of it kept, the rest freed (with red cells
  // and a tracer about 270 B a vessel).
  std::optional<FlowTransport::Outcome> carried;
  if (transport) {
    carried = transport->take_outcome();
    pulsatile.end_transport();
    transport.reset();
  }
  // It lay in the allocator's heap (a large block is mapped on its own only where the heap
  // has no room left for it), whose freed pages stay resident until given back: the results'
  // tables would be laid on top of them. (The 0D state went, and its pages with it, at the
  // run's end: PulsatileRun::run. Both together, the million-vessel tree with red cells: 775
  // MB before the results, 283 MB after.)
  return_free_memory();
  {  // the table (0.9 GB on the full tree) is freed before the last cycle is copied below
    VesselTable results = last.vessels.empty() ? VesselTable()
                                               : vessel_results(net, run, last, analysis_frequency(driving), config.solver.threads);
    if (carried && !last.vessels.empty())
      report_transport(net, *carried, pulsatile.last_red_cells(), pulsatile.red_cell_change(),
                       static_cast<double>(plan.transport_every) * dt, results, info);
    if (!last.vessels.empty()) info["statistics"] = group_statistics(net, results, config.solver.threads);
    write_results(dir, {info, results, last, boundary_flows(net, run, last), &pulsatile.probes(), config.solver.threads},
                  config.results_format);
    if (config.vtk && !last.vessels.empty()) write_results_vtk(dir / "results.vtp", net, results, config.vtk_keep);
  }
  folder->publish();

  result.error = status == RunStatus::broken_down ? in_words(pulsatile.breakdown(), config.words) : failure;
  result.cycles_done = pulsatile.cycles_done();
  result.has_change = pulsatile.has_change();
  if (result.has_change) {
    result.change = pulsatile.change().change;
    result.slowest_vessel = net.id[pulsatile.change().vessel];
  }
  result.time_step = dt;
  result.steps_per_cycle = steps_per_cycle;
  const bool with_numbers = result.outcome == RunOutcome::complete || result.outcome == RunOutcome::not_periodic;
  if (with_numbers) say_results(net, run, config, pulsatile, carried ? &*carried : nullptr, wall, observer);
  // Moved, not copied: the whole cycle's records (64 B a vessel) at the run's end.
  result.last_cycle = pulsatile.take_last_cycle();
  return result;
}

}  // namespace

RunResult run_pulsatile(const Network& net, const RunConfiguration& config, RunObserver& observer) {
  return pulsatile(net, config, observer, nullptr);
}

RunResult run_pulsatile(Network&& net, const RunConfiguration& config, RunObserver& observer) {
  return pulsatile(net, config, observer, &net);
}

void run_steady(const Network& net, const RunConfiguration& config, RunObserver& observer) {
  SteadyRunRequest request;
  request.input = config.network_name;
  request.out_dir = config.out_dir;
  request.rheology_override = config.solver.rheology_override;
  request.vtk = config.vtk;
  request.vtk_keep = config.vtk_keep;
  request.phase_separation = config.red_cells == RedCells::transport;
  request.threads = config.solver.threads;
  request.results_format = config.results_format;
  request.network_in_slices = config.network_in_slices;
  run_steady(net, request, observer);
}

}  // namespace hemotree
