// hemosolve: pulsatile flow in a compliant network by the spectral/hp DG method.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <omp.h>

#include "core/errors.hpp"
#include "cli/interrupt.hpp"
#include "cli/setting_words.hpp"
#include "cli/tool.hpp"
#include "core/units.hpp"
#include "formats/network_io.hpp"
#include "formats/pressure_reference.hpp"
#include "formats/topology.hpp"
#include "formats/checkpoint_file.hpp"
#include "solver/output_folder.hpp"
#include "solver/probes.hpp"
#include "solver/pulsatile_run.hpp"
#include "pulse/pulse_solver.hpp"
#include "solver/run_estimate.hpp"
#include "solver/run_outcome.hpp"
#include "solver/run_report.hpp"
#include "solver/steady_run.hpp"
#include "solver/tracer_spec.hpp"
#include "solver/transport_report.hpp"
#include "physics/phase_separation.hpp"

using namespace hemotree;

namespace {

constexpr double one_day = 86400;
constexpr double most_steps_per_cycle = 1e12;  // beyond any machine's reach, and size_t's range is safe
// The scheme's own mass balance: round-off plus the junctions' Newton tolerance (1e-12 of
// the flow; docs/solver.md). Far above both and far below any error that changes a result.
constexpr double conservation_tolerance = 1e-8;
// Steady or mean pressures outside this band are not physiological [mmHg].
constexpr double physiological_low = 0, physiological_high = 300;

// The network's arrays that shape the solution: a checkpoint of another network is refused.
std::uint64_t network_fingerprint(const Network& net) {
  Fingerprint f;
  f.add(net.id);
  f.add(net.from);
  f.add(net.to);
  f.add(net.length);
  f.add(net.diameter);
  f.add(net.wall_thickness);
  f.add(net.youngs_modulus);
  f.add(net.beta);
  f.add(net.reference_pressure);
  if (net.blood) f.add(to_json(*net.blood).dump());
  if (net.inlet) f.add(to_json(*net.inlet).dump());
  for (const Outlet& o : net.outlets) f.add(to_json(o).dump() + std::to_string(o.vessel));
  for (const NodeBoundary& b : net.boundaries) f.add(to_json(b, net.node_id[static_cast<std::size_t>(b.node)]).dump());
  f.add(net.distal_diameter);
  return f.value();
}

void check_range(double value, const Interval& range, const std::string& flag, std::string_view unit = "") {
  if (!range.contains(value))
    throw InputError(flag + " must lie in " + describe(range, unit) + " (got " +
                     (unit.empty() ? format_rounded(value) : format_quantity(value, unit)) + ")");
}

void check_count(long long value, long long low, long long high, const std::string& flag) {
  if (value < low || value > high)
    throw InputError(flag + " must lie in [" + std::to_string(low) + ", " + std::to_string(high) + "] (got " +
                     std::to_string(value) + ")");
}

std::string plural(std::size_t count, const std::string& noun) {
  return std::to_string(count) + " " + noun + (count == 1 ? "" : "s");
}

// Warns when pressures leave the physiological band, with the likely cause.
void warn_unphysiological(double low, double high, std::int64_t vessel, const Network& net, const char* what) {
  if (!std::isfinite(low) || !std::isfinite(high)) return;
  if (low >= physiological_low * pascal_per_mmhg && high <= physiological_high * pascal_per_mmhg) return;
  warn(std::string(what) + " reach " + format_quantity(high, "mmHg") + " (lowest " + format_quantity(low, "mmHg") +
       ", at vessel " + std::to_string(vessel) + "), outside a physiological 0 to 300 mmHg: " +
       (net.inlet ? "the inlet's mean flow (" + format_quantity(net.inlet->waveform.mean_value(), "ml/min") +
                        ") is likely wrong for this network's size (vprune --mean-flow sets it)"
                  : std::string("the boundary flows and pressures are likely wrong for this network")));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Solve 1D pulsatile blood flow in a compliant vascular network (spectral/hp "
               "discontinuous Galerkin) and report flows, pressures and pulsatility.",
               "hemosolve"};
  std::string input, out_dir, resume_dir, rheology, scheme = "etd2", start = "steady", dt_text,
      sample_text = "1ms", external_text = "10mmHg", degree_text = "auto", model = "auto", vtk_min_text;
  int cycles = 1, max_cycles = 50, frames = 0, checkpoint_every = 0;
  double periodic_tol = 0;
  std::vector<std::string> probe_texts;
  bool quiet = false, vtk = false, balance = true, force = false, steady = false;
  SolverOptions options;
  const int cores = omp_get_num_procs();
  app.add_option("network", input, "network file (vnet JSON), - for standard input")->required();
  app.add_option("--out", out_dir,
                                    "folder for summary.json, probes.csv, results.vtp and frames/; written as "
                                    "OUT.partial and renamed to OUT when the run ends, so OUT never mixes two runs");
  app.add_option("--resume", resume_dir,
                 "continue the run whose results folder this is from its last checkpoint (same network and "
                 "options; --cycles and --max-cycles may grow)");
  app.add_option("--checkpoint-every", checkpoint_every,
                 "write the solver's whole state to OUT.partial/checkpoint.bin every N cycles, in [0, 100000] "
                 "(0: only when interrupted)")
      ->capture_default_str();
  app.add_option("--cycles", cycles, "cardiac cycles to run, in [1, 100000]")->capture_default_str();
  auto* periodic_option = app.add_option(
      "--until-periodic", periodic_tol,
      "run until every vessel's mean pressure changes less than this (relative, in (0, 1)) from one cycle to the next");
  app.add_option("--max-cycles", max_cycles, "upper bound for --until-periodic, in [1, 100000]")->capture_default_str();
  app.add_option("--probe", probe_texts, "record p, Q, A, u at vessel ID, fraction x in [0, 1] along it (ID[:x], x 0.5 by default)");
  app.add_option("--sample-interval", sample_text, "time between probe samples, in (0, the period]")
      ->capture_default_str();
  app.add_option("--degree", degree_text,
                 "polynomial degree p in [0, 30] in every vessel, or auto: per vessel, --low-degree in vessels "
                 "much shorter than the pulse's wavelength (raised up to --raise-degree where the time step "
                 "allows), --high-degree elsewhere")
      ->capture_default_str();
  app.add_option("--low-degree", options.degree_rule.low, "auto: degree of acoustically short vessels, in [0, 30]")
      ->capture_default_str();
  app.add_option("--raise-degree", options.degree_rule.raise_to,
                 "auto: the most a short vessel is raised to at no cost in time step, in [0, 30]")
      ->capture_default_str();
  app.add_option("--high-degree", options.degree_rule.high, "auto: degree of the other vessels, in [0, 30]")
      ->capture_default_str();
  app.add_option("--linear-error", options.degree_rule.linear_error,
                 "auto: a short vessel whose steady pressure profile departs further than this from a "
                 "line (relative, in [0, inf]; inf: never; docs/solver.md) takes degree 2")
      ->capture_default_str();
  app.add_option("--model", model,
                 "vessel model: 1d (DG, waves), 0d (lumped R, L, C, implicit) or auto: 0d where a wave crosses "
                 "the vessel in less than --lumped-transit of the period and --lumped-rc holds, 1d elsewhere "
                 "(docs/solver.md §10)")
      ->capture_default_str();
  app.add_option("--lumped-transit", options.lumped_transit,
                 "auto: the wave transit time L/c, as a fraction of the period, below which a vessel is 0D, in [0, 1]")
      ->capture_default_str();
  app.add_option("--lumped-rc", options.lumped_rc,
                 "auto: the largest w R C (the vessel's resistance times its compliance at the pulse's "
                 "fundamental: the pressure's diffusion along a viscous vessel) of a 0D vessel, in [0, inf]")
      ->capture_default_str();
  app.add_option("--lumped-step", options.lumped_step,
                 "with 0D vessels: the step of the 0D vessels, as a fraction of the period, in (0, 0.1]; the 1D "
                 "vessels take substeps within it")
      ->capture_default_str();
  app.add_option("--lumped-passes", options.lumped_passes,
                 "with 0D vessels: linear solves per 0D step, in [1, 10]: 1 takes R, L and C at the state "
                 "extrapolated to the step's end (second order); each more pass takes them again at the last "
                 "solution (Picard)")
      ->capture_default_str();
  app.add_option("--elements", options.elements, "elements per vessel, in [1, 1000]")->capture_default_str();
  app.add_option("--dt", dt_text,
                 "time step, at most the stability limit unless --force (default: from the CFL and friction limits)");
  app.add_option("--cfl", options.cfl,
                 "fraction of the wave-speed (Courant) stability limit of the degree and scheme, in (0, 1] "
                 "(above 1 only with --force)")
      ->capture_default_str();
  app.add_option("--scheme", scheme, "time scheme: etd2 (Adams-Bashforth 2 with exact friction), ab2 (the paper's) or rk4")->capture_default_str();
  app.add_option("--rheology", rheology, "pries or newtonian (default: the network's blood)");
  app.add_option("--start", start, "initial state: steady (Poiseuille solution) or rest")->capture_default_str();
  app.add_option("--external-pressure", external_text, "interstitial pressure for the wall laws, in [-100, 100] mmHg")
      ->capture_default_str();
  app.add_option("--thick-wall-ratio", options.thick_wall_ratio, "h/D above which a wall is thick, in (0, 10]")
      ->capture_default_str();
  app.add_option("--threads", options.threads,
                 "threads over elements, in [1, " + std::to_string(cores) +
                     "] (this machine's cores; use the idle ones: results agree to round-off)")
      ->capture_default_str();
  app.add_flag("--vtk", vtk, "also write the network with every per-vessel result as VTK (results.vtp, for ParaView)");
  app.add_option("--vtk-min-diameter", vtk_min_text,
                 "--vtk and --frames write only the vessels of at least this diameter (e.g. 20um; a "
                 "full tree's millions of capillaries are more than ParaView wants)");
  app.add_option("--frames", frames,
                 "write N frames of the last cycle (p, Q, A, u per vessel) as a ParaView time series "
                 "(frames/frames.pvd), N in [0, 10000] and at most the steps of a cycle");
  app.add_flag("--balance-compliances,!--no-balance-compliances", balance,
               "at each cycle end, move the network's compliances (vessels and RCR capacitors) to where "
               "their mean filling over the cycle says the periodic state lies (docs/solver.md; on by default)");
  app.add_flag("--force", force,
               "run even with a --dt or --cfl above the stability limit, an estimated wall time above a day, or "
               "over the checkpoint a killed run left in OUT.partial");
  auto* steady_flag = app.add_flag(
      "--steady", steady,
      "the steady state alone, vessels at their file diameters (what NetFlow computes): flows, pressures and wall "
      "shear stress in the same files as a run; any connected network with boundaries at nodes");
  std::string red_cells = "fixed";
  app.add_option("--red-cells", red_cells,
                 "fixed (the blood's hematocrit in every vessel) or transport: red cells split by the "
                 "Pries-Secomb law at diverging bifurcations and mixed where blood meets; with --steady each "
                 "vessel's viscosity at its own hematocrit (what NetFlow computes), in a pulsatile run carried "
                 "by the flow with the Fahraeus effect (docs/transport.md)")
      ->capture_default_str();
  std::vector<std::string> tracer_texts;
  app.add_option("--tracer", tracer_texts,
                 "an indicator carried by the flow (repeatable): name=N,carrier=plasma|cells|blood,"
                 "at=inlet|node:ID|vessel:ID,shape=bolus|step,start=T,duration=T,concentration=C; its "
                 "concentration at the probes in probes.csv, its arrival, peak and mean transit time per vessel "
                 "(docs/transport.md)");
  double transport_step = 5e-3;
  app.add_option("--transport-step", transport_step,
                 "the red-cell transport's step as a fraction of the period (implicit: any length is stable; "
                 "shorter fronts spread less), at least the flow's step")
      ->capture_default_str();
  std::vector<std::string> pressure_at_texts;
  app.add_option("--pressure-at", pressure_at_texts,
                 "NODE=PRESSURE (e.g. 12=10mmHg): fixes the pressure level of a connected part whose boundaries are "
                 "flows only and balance, at that node (repeatable; a measured network's fragment, docs/import.md)");
  app.add_flag("--quiet", quiet, "no progress lines or notes (warnings and errors still)");
  app.set_version_flag("--version", std::string("hemosolve ") + HEMOTREE_VERSION);

  for (const char* pulsatile_only : {"--resume", "--checkpoint-every", "--cycles", "--until-periodic", "--max-cycles",
                                     "--probe", "--frames", "--dt", "--start", "--transport-step", "--tracer"})
    steady_flag->excludes(app.get_option(pulsatile_only));

  return run_tool(app, argc, argv, hemosolve_words(), [&] {
    // ---- every flag, before any work -------------------------------------------------
    if (out_dir.empty() && resume_dir.empty()) throw InputError("--out DIR is required (or --resume DIR)");
    if (!resume_dir.empty() && !out_dir.empty() &&
        std::filesystem::absolute(out_dir).lexically_normal() != std::filesystem::absolute(resume_dir).lexically_normal())
      throw InputError("--resume " + resume_dir + " continues the run in that folder; --out must name it too or be left out");
    if (out_dir.empty()) out_dir = resume_dir;
    check_count(cycles, 1, 100000, "--cycles");
    check_count(max_cycles, 1, 100000, "--max-cycles");
    check_count(checkpoint_every, 0, 100000, "--checkpoint-every");
    check_count(frames, 0, 10000, "--frames");
    const bool until_periodic = periodic_option->count() > 0;
    if (until_periodic) check_range(periodic_tol, {0, 1, true, true}, "--until-periodic");
    if (scheme == "rk4") options.scheme = TimeScheme::runge_kutta4;
    else if (scheme == "ab2") options.scheme = TimeScheme::adams_bashforth2;
    else if (scheme == "etd2") options.scheme = TimeScheme::exponential_ab2;
    else throw InputError("--scheme must be etd2, ab2 or rk4 (got '" + scheme + "')");
    if (model == "auto") options.model = ModelChoice::automatic;
    else if (model == "1d") options.model = ModelChoice::one_d;
    else if (model == "0d") options.model = ModelChoice::zero_d;
    else throw InputError("--model must be auto, 1d or 0d (got '" + model + "')");
    check_range(options.lumped_transit, {0, 1}, "--lumped-transit");
    check_range(options.lumped_rc, {0, INFINITY}, "--lumped-rc");
    check_range(options.lumped_step, {0, 0.1, true, false}, "--lumped-step");
    check_count(options.lumped_passes, 1, 10, "--lumped-passes");
    if (start == "rest") options.steady_start = false;
    else if (start != "steady") throw InputError("--start must be steady or rest (got '" + start + "')");
    if (!rheology.empty()) {
      if (rheology == "pries") options.rheology_override = static_cast<int>(Rheology::pries);
      else if (rheology == "newtonian") options.rheology_override = static_cast<int>(Rheology::newtonian);
      else throw InputError("--rheology must be pries or newtonian (got '" + rheology + "')");
    }
    if (!dt_text.empty()) options.dt = parse_quantity(dt_text, Dimension::time, "--dt", {0, 1, true, false}, "s");
    check_range(options.cfl, {0, force ? 100.0 : 1.0, true, false}, force ? "--cfl (with --force)" : "--cfl");
    if (degree_text != "auto") {
      std::size_t used = 0;
      try {
        options.degree = std::stoi(degree_text, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used == 0 || used != degree_text.size() || options.degree < 0 || options.degree > 30)
        throw InputError("--degree must be auto or a whole number in [0, 30] (got '" + degree_text + "')");
    }
    check_count(options.degree_rule.low, 0, 30, "--low-degree");
    check_count(options.degree_rule.raise_to, 0, 30, "--raise-degree");
    check_count(options.degree_rule.high, 0, 30, "--high-degree");
    check_range(options.degree_rule.linear_error, {0, INFINITY}, "--linear-error");  // inf: never degree 2
    check_count(options.elements, 1, 1000, "--elements");
    check_count(options.threads, 1, cores, "--threads");
    check_range(options.thick_wall_ratio, {0, 10, true, false}, "--thick-wall-ratio");
    options.external_pressure = parse_quantity(external_text, Dimension::pressure, "--external-pressure",
                                               {-100 * pascal_per_mmhg, 100 * pascal_per_mmhg}, "mmHg");
    const double sample_interval =
        parse_quantity(sample_text, Dimension::time, "--sample-interval", {0, 1e6, true, false}, "s");

    // Ctrl-C and kill are answered at a step's end from here on (cli/interrupt.hpp).
    InterruptRequests interrupts;
    Network net = read_network(input);
    for (const std::string& text : pressure_at_texts) {
      const auto eq = text.find('=');
      if (eq == std::string::npos)
        throw InputError("--pressure-at must be NODE=PRESSURE, e.g. 12=10mmHg (got '" + text + "')");
      const std::int64_t node = parse_integer(text.substr(0, eq), "--pressure-at NODE",
                                              std::numeric_limits<std::int64_t>::min(),
                                              std::numeric_limits<std::int64_t>::max());
      const double pressure = parse_quantity(text.substr(eq + 1), Dimension::pressure, "--pressure-at PRESSURE",
                                             {-1e5, 1e5}, "mmHg");
      const ConnectedPart part = fix_pressure_at(net, node, pressure);
      if (!quiet)
        note("--pressure-at " + text + ": the pressure level of " + part_name(part) + " (" + flow_balance(part) + ")");
    }
    std::vector<std::uint8_t> vtk_keep;
    if (!vtk_min_text.empty()) {
      if (!vtk && frames == 0) throw InputError("--vtk-min-diameter applies to --vtk and --frames only");
      const double low = parse_quantity(vtk_min_text, Dimension::length, "--vtk-min-diameter", {0, 1}, "um");
      vtk_keep.resize(net.vessel_count());
      std::size_t kept = 0;
      for (std::size_t v = 0; v < net.vessel_count(); ++v) kept += (vtk_keep[v] = net.diameter[v] >= low ? 1 : 0);
      if (kept == 0)
        throw InputError("--vtk-min-diameter " + vtk_min_text + " keeps no vessel (the largest is " +
                         format_quantity(*std::max_element(net.diameter.begin(), net.diameter.end()), "um") + ")");
      if (!quiet)
        note("--vtk-min-diameter " + vtk_min_text + ": the VTK output shows " + std::to_string(kept) + " of the " +
             std::to_string(net.vessel_count()) + " vessels (summary.json and vessels.csv hold all)");
    }
    if ((vtk || frames > 0) && net.x.empty())
      throw InputError("--vtk and --frames need node coordinates (x, y, z) in the network file");
    if (red_cells != "fixed" && red_cells != "transport")
      throw InputError("--red-cells must be fixed or transport (got '" + red_cells + "')");
    std::vector<TracerSpec> tracers;
    for (const auto& text : tracer_texts) tracers.push_back(parse_tracer(text, net, static_cast<int>(tracers.size()) + 1));
    for (std::size_t i = 0; i < tracers.size(); ++i)
      for (std::size_t j = 0; j < i; ++j)
        if (tracers[i].name == tracers[j].name) throw InputError("--tracer: two tracers named " + tracers[i].name);
    if (!(transport_step > 0 && transport_step <= 0.5))
      throw InputError("--transport-step " + format_rounded(transport_step) + ": accepted range (0, 0.5] of the period");
    if (steady) {
      SteadyRunRequest request;
      request.input = input;
      request.out_dir = out_dir;
      request.rheology_override = options.rheology_override;
      request.vtk = vtk;
      request.vtk_keep = vtk_keep;
      request.quiet = quiet;
      request.phase_separation = red_cells == "transport";
      run_steady(net, request);
      return 0;
    }
    if (!net.inlet && net.boundaries.empty())
      throw InputError("the network has no \"inlet\": hemosolve needs one (vprune adds it), or \"boundaries\"");
    // The common period of the time-varying boundary conditions (1 s where all are constant).
    const Waveform driving = driving_waveform(net);
    const double period = driving.period;
    check_range(sample_interval, {0, period, true, false}, "--sample-interval", "s");
    std::vector<Probe> probe_list;
    for (const auto& t : probe_texts) probe_list.push_back(parse_probe(t, net));
    OutputFolder folder(out_dir);
    std::string checkpoint_bytes, checkpoint_source;
    if (!resume_dir.empty()) {
      const auto file = folder.latest_checkpoint();
      if (!file)
        throw InputError("--resume " + resume_dir + ": no checkpoint.bin in it or in " + folder.staging().string() +
                         " (a run writes one when interrupted, or every N cycles with --checkpoint-every N)");
      checkpoint_bytes = read_checkpoint_file(*file);
      checkpoint_source = file->string();
    }
    if (resume_dir.empty() && !force && folder.latest_checkpoint() &&
        folder.latest_checkpoint()->parent_path() == folder.staging())
      throw InputError(folder.staging().string() + " holds the checkpoint of a run that was killed: --resume " +
                       out_dir + " continues it; --force (or removing that folder) starts afresh");
    auto stop_if_interrupted = [&] {  // before the time loop nothing is written: just stop
      if (const int s = interrupts.poll()) {
        warn(std::string("interrupted by ") + InterruptRequests::name(s) + " before the first step: nothing written");
        throw InterruptedExit{InterruptRequests::exit_status(s)};
      }
    };
    stop_if_interrupted();

    // ---- the discretisation, its step and its cost ---------------------------------------
    PulseSolver run(net, options);  // the steady solve: minutes on the full tree
    stop_if_interrupted();
    const bool beyond_limit = options.dt > 0 && options.dt > run.stable_dt() * (1 + 1e-9);
    const std::string over_limit =
        beyond_limit ? "--dt " + format_quantity(options.dt, "s") + " is " + format_rounded(options.dt / run.stable_dt()) +
                           " times the " + (run.lumped_count() > 0 ? "0D step's accuracy limit " : "stability limit ") +
                           format_quantity(run.stable_dt(), "s") + " (" +
                           in_words(run.stable_dt_reason(), hemosolve_words()) + ")"
                     : std::string();
    if (beyond_limit && !force)
      throw InputError(over_limit + "; the solution would blow up or be wrong: use a --dt of at most the limit, or "
                       "--force to run it anyway");
    const double steps_wanted = std::ceil(period / run.dt() - 1e-9);
    if (!(steps_wanted <= most_steps_per_cycle))
      throw InputError("a time step of " + format_quantity(run.dt(), "s") + " (" + in_words(run.dt_reason(), hemosolve_words()) + ") needs " +
                       format_rounded(steps_wanted) + " steps per cycle: no run can finish; check that vessel's "
                       "wall and length, and the inlet's flow");
    const auto steps_per_cycle = static_cast<std::size_t>(steps_wanted);
    const double dt = period / static_cast<double>(steps_per_cycle);  // a whole number per cycle
    const std::string dt_reason = in_words(run.dt_reason(), hemosolve_words());
    run.set_time_step(dt);  // slightly smaller, so that cycles end exactly on a step
    if (static_cast<std::size_t>(frames) > steps_per_cycle)
      throw InputError("--frames " + std::to_string(frames) + " exceeds the " + std::to_string(steps_per_cycle) +
                       " steps of a cycle");
    std::map<int, std::size_t> degrees;  // elements per degree
    for (std::size_t v = 0; v < net.vessel_count(); ++v)
      if (!run.is_lumped(v)) degrees[run.degree(v)] += static_cast<std::size_t>(options.elements);
    std::vector<double> elements_of_degree(static_cast<std::size_t>(run.max_degree()) + 1, 0.0);
    std::string degree_list;
    for (const auto& [p, count] : degrees) {
      elements_of_degree[static_cast<std::size_t>(p)] = static_cast<double>(count);
      degree_list += (degree_list.empty() ? "" : ", ") + std::to_string(count) + " of degree " + std::to_string(p);
    }
    const int planned = until_periodic ? max_cycles : cycles;
    const double lumped = static_cast<double>(run.lumped_count()), substeps = run.substeps();
    const RunEstimate per_cycle =
        estimate_run(elements_of_degree, static_cast<double>(steps_per_cycle), options.threads, substeps, lumped);
    const RunEstimate whole = estimate_run(elements_of_degree, static_cast<double>(steps_per_cycle) * planned,
                                           options.threads, substeps, lumped);
    if (per_cycle.seconds > one_day && !force)
      throw InputError("one cycle would take about " + describe_duration(per_cycle.seconds) + " (" +
                       format_rounded(static_cast<double>(steps_per_cycle)) + " steps of " + format_quantity(dt, "s") +
                       ", set by the " + dt_reason + "; " + plural(run.element_count(), "element") +
                       "): refused, more than a day. Check that vessel's wall and length and the inlet's "
                       "flow, use fewer --elements or a lower --degree, or --force to run it anyway");
    const std::size_t one_d = net.vessel_count() - run.lumped_count();
    if (!quiet)
      note(plural(one_d, "vessel") + " 1D, " + std::to_string(run.lumped_count()) + " 0D (--model " + model + ")" +
           (run.lumped_count() > 0 && one_d > 0
                ? "; " + std::to_string(run.substeps()) + " 1D substeps of " + format_quantity(run.substep(), "s") +
                      " per step"
                : std::string()));
    if (!quiet)
      note("time step " + format_quantity(dt, "s") + " (" + dt_reason + "), " + std::to_string(steps_per_cycle) +
           " steps per cycle, " + plural(run.element_count(), "element") + (degree_list.empty() ? "" : ": ") + degree_list +
           "; estimated " + describe_duration(per_cycle.seconds) + " per cycle, " + describe_duration(whole.seconds) +
           (until_periodic ? " for at most " : " for ") + plural(planned, "cycle") + " on " +
           plural(options.threads, "thread"));
    if (whole.seconds > one_day && !quiet)
      warn("the whole run may take " + describe_duration(whole.seconds) +
           " (use --checkpoint-every N to be able to resume it)");

    // ---- what the run starts from, said as it is --------------------------------------------
    const bool steady_start = run.started_from_steady();
    if (options.steady_start && !steady_start)
      warn("no steady solution to start from (" + run.steady_refusal() + "): starting from rest" +
           (balance ? std::string(", without the compliance balance (it needs the steady network)") : std::string()));
    warn_unphysiological(run.steady_pressure_min(), run.steady_pressure_max(),
                         net.id[run.steady_pressure_max_vessel()], net, "steady pressures");

    // ---- the run ------------------------------------------------------------------------------
    std::ostringstream shaping;  // the options a checkpoint must share with the run resuming it
    shaping.precision(std::numeric_limits<double>::max_digits10);  // every bit: 6 digits let 0.10000001 pass as 0.1
    shaping << "model " << model << " (" << options.lumped_transit << ", " << options.lumped_rc << ", "
            << options.lumped_step << ", " << options.lumped_passes << " passes), scheme "
            << scheme << ", degree " << degree_text << " (" << options.degree_rule.low << "/"
            << options.degree_rule.raise_to << "/" << options.degree_rule.high << ", linear error "
            << options.degree_rule.linear_error << "), elements " << options.elements << ", time step " << dt
            << ", rheology " << to_string(run.blood().rheology) << ", start " << start << ", external pressure "
            << options.external_pressure << " Pa, thick wall ratio " << options.thick_wall_ratio
            << ", balance " << (balance ? "on" : "off") << ", sample interval " << sample_interval << " s, probes";
    for (const auto& t : probe_texts) shaping << ' ' << t;
    shaping << ", red cells " << red_cells;
    for (const auto& t : tracer_texts) shaping << ", tracer " << t;
    if (red_cells == "transport" || !tracer_texts.empty()) shaping << ", transport every " << transport_step << " of the period";
    RunPlan plan;
    plan.cycles = cycles;
    plan.until_periodic = until_periodic;
    plan.periodic_tolerance = periodic_tol;
    plan.max_cycles = max_cycles;
    plan.balance_compliances = balance;
    plan.frames = frames;
    plan.vtk_keep = vtk_keep;
    plan.steps_per_cycle = steps_per_cycle;
    plan.sample_every = std::max<std::size_t>(1, static_cast<std::size_t>(std::llround(sample_interval / dt)));
    plan.checkpoint_every = checkpoint_every;
    plan.options = shaping.str();
    plan.fingerprint = network_fingerprint(net);
    plan.live_progress = !quiet && stderr_is_terminal();
    plan.log_progress = !quiet && !stderr_is_terminal();
    plan.longest_cycle = force ? 0 : one_day;
    std::optional<FlowTransport> transport;
    if (red_cells == "transport" || !tracers.empty()) {
      FlowTransportOptions carried;
      carried.tracers = tracers;
      transport.emplace(net, run, red_cells == "transport" ? carried : red_cells_fixed(carried));
      plan.transport_every = std::max<std::size_t>(
          1, static_cast<std::size_t>(std::llround(transport_step * static_cast<double>(steps_per_cycle))));
      if (!quiet)
        note(std::string(red_cells == "transport" ? "red cells" : "") +
             (red_cells == "transport" && !tracers.empty() ? " and " : "") +
             (tracers.empty() ? "" : plural(tracers.size(), "tracer")) + " carried on " +
             plural(transport->cell_count(), "cell") + ", a transport step every " +
             plural(plan.transport_every, "flow step"));
    }
    PulsatileRun pulsatile(net, run, std::move(probe_list), plan, folder.staging(), transport ? &*transport : nullptr);
    if (!checkpoint_bytes.empty()) {
      pulsatile.resume(checkpoint_bytes, checkpoint_source);
      if (!quiet)
        note("resuming from " + checkpoint_source + " after " + std::to_string(pulsatile.cycles_done()) +
             " cycles (t = " + format_quantity(run.time(), "s") + ")");
    }
    folder.open(pulsatile.keeps_frames());  // a resume at the run's end keeps the killed run's last frames
    if (frames > 0) {
      std::error_code ec;
      std::filesystem::create_directories(folder.staging() / "frames", ec);
      if (ec) throw IoError("cannot create " + (folder.staging() / "frames").string() + ": " + ec.message());
    }
    const auto started = std::chrono::steady_clock::now();
    RunStatus status = pulsatile.run(interrupts);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    const CycleSummary& last = pulsatile.last_cycle();

    // A run is complete only when its numbers say so.
    std::string failure;
    // A forced step beyond the limit runs, for whoever wants to see what it gives, but its
    // numbers are outside the scheme's accuracy: never complete.
    if (beyond_limit && (status == RunStatus::complete || status == RunStatus::not_periodic))
      failure = over_limit + ", forced: the results are outside the scheme's accuracy";
    if (failure.empty() && (status == RunStatus::complete || status == RunStatus::not_periodic)) {
      if (!(std::abs(last.conservation_error) < conservation_tolerance))
        failure = "the scheme lost mass: (in - out - stored) / in = " + format_rounded(last.conservation_error) +
                  " over the last cycle, above " + format_rounded(conservation_tolerance);
      // Each prescribed flow's mean against what went through it (a zero mean within 1e-6
      // of the flow in).
      const std::vector<NodeBoundary>& list = run.boundary_list();
      for (std::size_t i = 0; i < list.size() && failure.empty() && i < last.boundary_mean_flow.size(); ++i) {
        if (list[i].type != BoundaryType::flow) continue;
        const double prescribed = list[i].waveform.mean_value(), got = last.boundary_mean_flow[i];
        if (std::abs(got - prescribed) <= 1e-2 * std::abs(prescribed) + 1e-6 * std::abs(last.inlet_mean_flow)) continue;
        const bool inlet = net.inlet && net.boundaries.empty();
        failure = (inlet ? std::string("the inlet's mean flow")
                         : "the mean flow into node " + std::to_string(net.node_id[static_cast<std::size_t>(list[i].node)])) +
                  " over the last cycle is " + format_quantity(got, "ml/min") + " where the waveform prescribes " +
                  format_quantity(prescribed, "ml/min") + ": the time step cannot follow the pulse";
      }
    }

    const RunOutcome outcome = !failure.empty()                     ? RunOutcome::failed
                               : status == RunStatus::broken_down  ? RunOutcome::broken_down
                               : status == RunStatus::interrupted  ? RunOutcome::interrupted
                               : status == RunStatus::not_periodic ? RunOutcome::not_periodic
                                                                   : RunOutcome::complete;
    nlohmann::json run_info = {{"tool", "hemosolve"}, {"version", HEMOTREE_VERSION},
                               {"network", input},
                               {"degree", options.degree == SolverOptions::automatic ? nlohmann::json("auto")
                                                                                     : nlohmann::json(options.degree)},
                               {"elements_per_vessel", options.elements}, {"scheme", scheme},
                               {"model", model},
                               {"vessels_1d", one_d},
                               {"vessels_0d", run.lumped_count()},
                               {"substeps", run.substeps()},
                               {"threads", options.threads},
                               {"rheology", to_string(run.blood().rheology)},
                               {"red_cells", red_cells},
                               {"mean_cell_volume", run.blood().mean_cell_volume},
                               {"start", steady_start ? "steady" : "rest"},
                               {"start_requested", start},
                               {"balance_compliances", balance && steady_start},
                               {"period", period},
                               {"pulse_frequency", pulse_frequency(driving)},
                               {"analysis_frequency", analysis_frequency(driving)},
                               {"time_step", dt}, {"time_step_limit", dt_reason},
                               {"steps_per_cycle", steps_per_cycle},
                               {"status", to_string(outcome)},
                               {"cycles", pulsatile.cycles_done()},
                               {"steps", static_cast<std::uint64_t>(pulsatile.cycles_done()) * steps_per_cycle},
                               {"compliance_balances", pulsatile.compliance_balances()},
                               {"wall_time", wall}};
    if (!steady_start && options.steady_start) run_info["steady_refusal"] = run.steady_refusal();
    for (const auto& [p, count] : degrees) run_info["elements_of_degree"][std::to_string(p)] = count;
    if (pulsatile.has_change()) {
      run_info["periodic_change"] = pulsatile.change().change;
      run_info["slowest_vessel"] = net.id[pulsatile.change().vessel];
    }
    if (!failure.empty()) run_info["error"] = failure;
    if (!last.boundary_mean_flow.empty()) {
      // Each boundary's mean flow into the network over the last cycle (as --steady reports).
      run_info["boundaries"] = nlohmann::json::array();
      for (std::size_t i = 0; i < run.boundary_list().size(); ++i) {
        const NodeBoundary& b = run.boundary_list()[i];
        run_info["boundaries"].push_back({{"node", net.node_id[static_cast<std::size_t>(b.node)]},
                                          {"type", to_string(b.type)},
                                          {"flow", last.boundary_mean_flow[i]}});
        if (!b.is_outlet()) run_info["boundaries"].back()["hematocrit"] = b.entering_hematocrit(run.blood());
      }
    }
    if (status == RunStatus::broken_down) run_info["error"] = in_words(pulsatile.breakdown(), hemosolve_words());
    if (status == RunStatus::interrupted)
      run_info["error"] = std::string("interrupted by ") + InterruptRequests::name(pulsatile.signal()) +
                          "; resume with --resume " + out_dir;

    if (status == RunStatus::too_long) {
      folder.discard();
      const double cycle = pulsatile.measured_step() * static_cast<double>(steps_per_cycle);
      throw InputError("one cycle would take about " + describe_duration(cycle) + " (measured over its first steps: " +
                       format_quantity(pulsatile.measured_step(), "s") + " a step, " +
                       format_rounded(static_cast<double>(steps_per_cycle)) +
                       " steps): stopped, more than a day. Use fewer --elements or a lower --degree, --threads, "
                       "or --force to run it anyway");
    }
    // Nothing computed, nothing kept: DIR stays as it was.
    if (status == RunStatus::broken_down && last.vessels.empty()) {
      folder.discard();
      throw InputError(in_words(pulsatile.breakdown(), hemosolve_words()));
    }
    const std::filesystem::path dir = folder.staging();
    if (status == RunStatus::interrupted || checkpoint_every > 0) pulsatile.write_checkpoint();
    pulsatile.probes().write(dir / "probes.csv");
    VesselTable results =
        last.vessels.empty() ? VesselTable() : vessel_results(net, run, last, analysis_frequency(driving));
    const RedCellCycle& cells = pulsatile.last_red_cells();
    if (transport && !last.vessels.empty())
      report_transport(net, *transport, cells, pulsatile.red_cell_change(), static_cast<double>(plan.transport_every) * dt,
                       results, run_info);
    if (!last.vessels.empty()) run_info["statistics"] = group_statistics(net, results);
    write_summary(dir / "summary.json", run_info, results, last);
    write_vessel_table(dir / "vessels.csv", results);
    if (vtk && !last.vessels.empty()) write_results_vtk(dir / "results.vtp", net, results, vtk_keep);
    folder.publish();

    if (status == RunStatus::interrupted) {
      warn(std::string("interrupted by ") + InterruptRequests::name(pulsatile.signal()) + " after " +
           plural(pulsatile.cycles_done(), "cycle") + ": " + out_dir +
           (pulsatile.cycles_done() > 0 ? " holds the results of the last whole cycle and its checkpoint"
                                        : " holds the checkpoint of the start (no cycle was completed)") +
           "; --resume " + out_dir + " continues");
      return exit_status(outcome, pulsatile.signal());
    }
    if (status == RunStatus::broken_down) throw InputError(in_words(pulsatile.breakdown(), hemosolve_words()));
    if (!failure.empty()) throw InputError("the results are wrong and marked failed in summary.json: " + failure);
    if (!quiet) {
      std::ostringstream m;
      m << plural(pulsatile.cycles_done(), "cycle") << " in " << describe_duration(wall);
      if (pulsatile.has_change())
        m << "; last cycle-to-cycle change " << format_rounded(pulsatile.change().change) << " (vessel "
          << net.id[pulsatile.change().vessel] << ")";
      m << "; results in " << out_dir;
      note(m.str());
    }
    // The red cells' own unrest, said plainly: a network can oscillate by itself (docs/transport.md).
    if (!quiet && transport && transport->reports_red_cells() && !cells.discharge.empty())
      note(red_cell_line(net, cells, pulsatile.red_cell_change()));
    double low = INFINITY, high = -INFINITY;
    std::size_t highest = 0;
    for (std::size_t v = 0; v < last.vessels.size(); ++v) {
      low = std::min(low, last.vessels[v].mean_pressure);
      if (last.vessels[v].mean_pressure > high) high = last.vessels[(highest = v)].mean_pressure;
    }
    warn_unphysiological(low, high, net.id[highest], net, "mean pressures");
    // A tracer whose injection the run never reached has no curves: said, not left to be found.
    for (std::size_t k = 0; transport && k < tracers.size(); ++k)
      if (const TracerTransport& moved = transport->tracer(k); moved.entered() + moved.injected() == 0)
        warn("tracer " + tracers[k].name + " never entered the network (its injection starts at t = " +
             format_quantity(tracers[k].start, "s") + ", the run ended at t = " + format_quantity(run.time(), "s") +
             "): its arrival, peak and transit times are null");
    if (outcome == RunOutcome::not_periodic)
      warn("not periodic within " + std::to_string(max_cycles) + " cycles (--max-cycles)" +
           (pulsatile.has_change() ? ": the last cycle changed by " + format_rounded(pulsatile.change().change) +
                                         " (vessel " + std::to_string(net.id[pulsatile.change().vessel]) + ")"
                                   : std::string()) +
           ", above --until-periodic " + format_rounded(periodic_tol) + "; exit status " +
           std::to_string(exit_status(outcome)));
    return exit_status(outcome);
  });
}
