// hemosolve: pulsatile flow in a compliant network by the spectral/hp DG method. This file
// is the command line alone: options bound into a RunConfiguration, texts translated into
// values, the run called (solver/pulsatile_call.hpp) and its outcome said and turned into
// the exit status; the run itself is a library call.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>
#include <omp.h>

#include "cli/interrupt.hpp"
#include "cli/setting_words.hpp"
#include "mpi/session.hpp"
#include "cli/tool.hpp"
#include "core/units.hpp"
#include "core/errors.hpp"
#include "formats/network_io.hpp"
#include "formats/network_slice.hpp"
#include "formats/pressure_reference.hpp"
#include "solver/linear_run.hpp"
#include "solver/outcome_lines.hpp"
#include "solver/pulsatile_call.hpp"
#include "solver/run_configuration.hpp"

using namespace hemotree;

namespace {

// The run's words on stderr ("hemosolve: ...", notes silenced by --quiet), its progress as a
// line redrawn on a terminal or a line per cycle in a log, and Ctrl-C and kill as requests.
class CommandLineObserver final : public RunObserver {
 public:
  CommandLineObserver(InterruptRequests& interrupts, bool quiet) : interrupts_(interrupts), quiet_(quiet) {}
  void note(const std::string& message) override {
    if (!quiet_) hemotree::note(message);
  }
  void warn(const std::string& message) override { hemotree::warn(message); }
  bool hears_notes() const override { return !quiet_; }
  ProgressStyle progress_style() const override {  // over MPI ranks rank 0's alone
    return quiet_ || world_rank() != 0 ? ProgressStyle::none : stderr_is_terminal() ? ProgressStyle::live : ProgressStyle::log;
  }
  void live_progress(int cycle, int planned, double time, double rate, double left) override {
    std::fprintf(stderr, "\rhemosolve: cycle %d/%d  t = %.4f s  %.0f steps/s  %.0f s left in this cycle   ", cycle,
                 planned, time, rate, left);
  }
  void clear_live_progress() override { std::fprintf(stderr, "\r\033[K"); }
  int poll_interrupt() override { return interrupts_.poll(); }
  std::string signal_name(int signal) const override { return InterruptRequests::name(signal); }

 private:
  InterruptRequests& interrupts_;
  bool quiet_;
};

// --pressure-at NODE=PRESSURE: the pressure level of a part whose boundaries are flows only.
void fix_pressures(Network& net, const std::vector<std::string>& texts, bool quiet) {
  for (const std::string& text : texts) {
    const auto eq = text.find('=');
    if (eq == std::string::npos)
      throw InputError("--pressure-at must be NODE=PRESSURE, e.g. 12=10mmHg (got '" + text + "')");
    const std::int64_t node = parse_integer(text.substr(0, eq), "--pressure-at NODE",
                                            std::numeric_limits<std::int64_t>::min(),
                                            std::numeric_limits<std::int64_t>::max());
    const double pressure =
        parse_quantity(text.substr(eq + 1), Dimension::pressure, "--pressure-at PRESSURE", {-1e5, 1e5}, "mmHg");
    const ConnectedPart part = fix_pressure_at(net, node, pressure);
    if (!quiet) note("--pressure-at " + text + ": the pressure level of " + part_name(part) + " (" + flow_balance(part) + ")");
  }
}

// --vtk-min-diameter: the vessels the VTK output shows.
std::vector<std::uint8_t> vtk_vessels(const Network& net, const std::string& text, bool quiet) {
  const double low = parse_quantity(text, Dimension::length, "--vtk-min-diameter", {0, 1}, "um");
  std::vector<std::uint8_t> keep(net.vessel_count());
  std::size_t kept = 0;
  for (std::size_t v = 0; v < net.vessel_count(); ++v) kept += (keep[v] = net.diameter[v] >= low ? 1 : 0);
  if (kept == 0)
    throw InputError("--vtk-min-diameter " + text + " keeps no vessel (the largest is " +
                     format_quantity(*std::max_element(net.diameter.begin(), net.diameter.end()), "um") + ")");
  if (!quiet)
    note("--vtk-min-diameter " + text + ": the VTK output shows " + std::to_string(kept) + " of the " +
         std::to_string(net.vessel_count()) + " vessels (summary.json and vessels.csv hold all)");
  return keep;
}

// The outcome said as the command line says it, and the exit status (solver/run_outcome.hpp).
int finish(const RunResult& result, const RunConfiguration& config) {
  if (!result.started) return InterruptRequests::exit_status(result.signal);
  if (const std::string error = outcome_error(result); !error.empty()) throw InputError(error);
  if (const std::string line = outcome_warning(result, config, InterruptRequests::name(result.signal)); !line.empty())
    warn(line);
  return exit_status(result.outcome, result.signal);
}

// The command line as given: numbers bound straight into the run's configuration, texts
// kept for translation once the network is read.
struct CommandLine {
  RunConfiguration config;
  std::string out_dir, resume_dir, rheology, scheme = "etd2", start = "periodic", dt_text, sample_text = "1ms",
      external_text = "10mmHg", degree_text = "auto", lumped_step_text = "auto", coupling_passes_text = "auto", settling_degree_text = "auto",
      model = "auto", vtk_min_text, red_cells = "fixed", format = "text";
  std::vector<std::string> probe_texts, tracer_texts, pressure_at_texts;
  bool quiet = false, steady = false, linear = false;
  CLI::Option* until_periodic = nullptr;
};

void bind_options(CLI::App& app, CommandLine& line, int cores) {
  RunConfiguration& config = line.config;
  SolverOptions& options = config.solver;
  std::string &input = config.network_name, &out_dir = line.out_dir, &resume_dir = line.resume_dir,
              &rheology = line.rheology, &scheme = line.scheme, &start = line.start, &dt_text = line.dt_text,
              &sample_text = line.sample_text, &external_text = line.external_text, &degree_text = line.degree_text,
              &lumped_step_text = line.lumped_step_text, &coupling_passes_text = line.coupling_passes_text,
              &settling_degree_text = line.settling_degree_text,
              &model = line.model, &vtk_min_text = line.vtk_min_text, &red_cells = line.red_cells,
              &format = line.format;
  int &cycles = config.cycles, &max_cycles = config.max_cycles, &frames = config.frames,
      &checkpoint_every = config.checkpoint_every;
  double &periodic_tol = config.periodic_tolerance, &transport_step = config.transport_step;
  std::vector<std::string> &probe_texts = line.probe_texts, &tracer_texts = line.tracer_texts,
                           &pressure_at_texts = line.pressure_at_texts;
  bool &vtk = config.vtk, &balance = config.balance_compliances, &force = config.force, &quiet = line.quiet,
       &steady = line.steady, &linear = line.linear;
  app.add_option("network", input, "network file (vnet, JSON or HDF5), - for standard input")->required();
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
  line.until_periodic = app.add_option(
      "--until-periodic", periodic_tol,
      "run until every vessel's mean pressure changes less than this (relative, in (0, 1)) from one cycle to the next");
  app.add_option("--max-cycles", max_cycles, "upper bound for --until-periodic, in [1, 100000]")->capture_default_str();
  app.add_option("--settling-step", config.settling_step,
                 "with --until-periodic and 0D vessels: first one settling cycle, not reported, with the 0D step N "
                 "times --lumped-step, and the compliance balance after it (docs/solver.md §6a); 0 or 1: none (the "
                 "default: the periodic start leaves it nothing to settle), in [0, 20]")
      ->capture_default_str();
  app.add_option("--settling-degree", settling_degree_text,
                 "with --until-periodic and 1D vessels: first one settling cycle, not reported, with the 1D vessels at "
                 "this degree at most (many times cheaper than a cycle of the run's), the compliance balance after it, "
                 "and the run from the state it leaves (docs/solver.md §6a); 0: none; auto: degree 2 where most "
                 "vessels are 1D (the large arteries) and it costs at most a third of a cycle; else in [0, 30]")
      ->capture_default_str();
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
  app.add_option("--lumped-sections", options.lumped_sections,
                 "auto: the most pi sections of a 0D vessel, in [1, 64]: a vessel whose w R C exceeds "
                 "--lumped-rc is cut into sections that each keep below it, where this many suffice, else it is "
                 "1D; 1: every such vessel 1D (with red cells or tracers: always 1)")
      ->capture_default_str();
  app.add_option("--lumped-step", lumped_step_text,
                 "with 0D vessels: the step of the 0D vessels, as a fraction of the period, in (0, 0.1], or auto: "
                 "a thousandth for each coupling pass; the 1D vessels take substeps within it")
      ->capture_default_str();
  app.add_option("--coupling-passes", coupling_passes_text,
                 "with 1D vessels ending on 0D ones: how many times a 0D step's 1D substeps are taken, each pass "
                 "after the first with the 0D prediction from the inflows the one before let through, in [1, 10], "
                 "or auto: the number that costs least per cycle, at most 4, or with --lumped-step given one per "
                 "thousandth of the period (docs/solver.md §10)")
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
  app.add_option("--start", start, "initial state: periodic (the linear periodic state about the steady solution, at t = 0), steady (the steady solution) or rest")->capture_default_str();
  app.add_option("--external-pressure", external_text, "interstitial pressure for the wall laws, in [-100, 100] mmHg")
      ->capture_default_str();
  app.add_option("--thick-wall-ratio", options.thick_wall_ratio, "h/D above which a wall is thick, in (0, 10]")
      ->capture_default_str();
  app.add_option("--threads", options.threads,
                 "threads over elements, in [1, " + std::to_string(cores) +
                     "] (this machine's cores; use the idle ones: results agree to round-off)")
      ->capture_default_str();
  app.add_option("--format", format,
                 "text: summary.json, vessels.csv and probes.csv; h5: summary.json (the run's facts) and results.h5 "
                 "(the vessels', boundaries' and probes' results as columns, for h5py and pandas)")
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
      "shear stress in the same files as a run; any connected network with boundaries at nodes; under mpirun -np P "
      "over P ranks (a tree: the same files byte for byte; loops: PETSc, to 1e-10)");
  auto* linear_flag = app.add_flag(
      "--linear", linear,
      "the linear periodic state about the steady one as the result, harmonic by harmonic (every vessel a "
      "transmission line, every outlet its impedance): the same files as a run, in seconds on 100,000 vessels and about 12 s on 3.8 million from and to HDF5 (two threads), for "
      "screening (docs/solver.md §6a gives its error against a run); under mpirun -np P over P ranks (a tree fed by its "
      "inflow: the same files byte for byte; any other network: PETSc, to 1e-10)");
  app.add_option("--harmonics", options.periodic_harmonics,
                 "the inflow's harmonics the linear periodic state takes (--linear, --start periodic), in [1, 1000]")
      ->capture_default_str();
  app.add_option("--red-cells", red_cells,
                 "fixed (the blood's hematocrit in every vessel) or transport: red cells split by the "
                 "Pries-Secomb law at diverging bifurcations and mixed where blood meets; with --steady each "
                 "vessel's viscosity at its own hematocrit (what NetFlow computes), in a pulsatile run carried "
                 "by the flow with the Fahraeus effect (docs/transport.md)")
      ->capture_default_str();
  app.add_option("--tracer", tracer_texts,
                 "an indicator carried by the flow (repeatable): name=N,carrier=plasma|cells|blood,"
                 "at=inlet|node:ID|vessel:ID,shape=bolus|step,start=T,duration=T,concentration=C; its "
                 "concentration at the probes in probes.csv, its arrival, peak and mean transit time per vessel "
                 "(docs/transport.md)");
  app.add_option("--transport-step", transport_step,
                 "the red-cell transport's step as a fraction of the period (implicit: any length is stable; "
                 "shorter fronts spread less), at least the flow's step")
      ->capture_default_str();
  app.add_option("--pressure-at", pressure_at_texts,
                 "NODE=PRESSURE (e.g. 12=10mmHg): fixes the pressure level of a connected part whose boundaries are "
                 "flows only and balance, at that node (repeatable; a measured network's fragment, docs/import.md)");
  app.add_flag("--quiet", quiet, "no progress lines or notes (warnings and errors still)");
  app.set_version_flag("--version", std::string("hemosolve ") + HEMOTREE_VERSION);

  for (const char* pulsatile_only : {"--resume", "--checkpoint-every", "--cycles", "--until-periodic", "--max-cycles",
                                     "--settling-step", "--settling-degree", "--probe", "--frames", "--dt", "--start", "--transport-step",
                                     "--tracer"})
    steady_flag->excludes(app.get_option(pulsatile_only));
  for (const char* time_stepped_only : {"--resume", "--checkpoint-every", "--cycles", "--until-periodic", "--max-cycles",
                                        "--settling-step", "--settling-degree", "--frames", "--dt", "--start", "--transport-step",
                                        "--tracer", "--steady",
                                        "--red-cells"})
    linear_flag->excludes(app.get_option(time_stepped_only));
}

// Every option checked before any work, the network read, the run called.
int run_command_line(CommandLine& line, int cores) {
  RunConfiguration& config = line.config;
  SolverOptions& options = config.solver;
  const std::string &out_dir = line.out_dir, &resume_dir = line.resume_dir, &vtk_min_text = line.vtk_min_text;
  const bool quiet = line.quiet, vtk = config.vtk;
  const int frames = config.frames;
  config.words = hemosolve_words();
  // Ctrl-C and kill are answered at a step's end from here on (cli/interrupt.hpp).
  InterruptRequests interrupts;
  CommandLineObserver observer(interrupts, quiet);
  // The options and the network, checked on every rank alike before any rank goes on to the
  // run (over MPI ranks a refusal is then every rank's: mpi/session.hpp).
  Network net;
  // Whether the network is an HDF5 file, as rank 0 finds it: a slice is read from one
  // (formats/network_slice.hpp), and every rank must take the same way.
  const bool network_in_hdf5 = lead_answer(world_rank() == 0 && is_hdf5_network_file(line.config.network_name));
  on_every_rank([&] {
    // ---- every option, before any work ----------------------------------------------------
    if (out_dir.empty() && resume_dir.empty()) throw InputError("--out DIR is required (or --resume DIR)");
    if (!resume_dir.empty() && !out_dir.empty() &&
        std::filesystem::absolute(out_dir).lexically_normal() != std::filesystem::absolute(resume_dir).lexically_normal())
      throw InputError("--resume " + resume_dir +
                       " continues the run in that folder; --out must name it too or be left out");
    config.out_dir = out_dir.empty() ? resume_dir : out_dir;
    config.resume = !resume_dir.empty();
    config.until_periodic = line.until_periodic->count() > 0;
    check_configuration(config);
    options.scheme = time_scheme_named(line.scheme);
    options.model = model_named(line.model);
    options.start = start_named(line.start);
    if (!line.rheology.empty()) options.rheology_override = static_cast<int>(rheology_named(line.rheology));
    options.degree = degree_named(line.degree_text);
    options.lumped_step = lumped_step_named(line.lumped_step_text);
    options.coupling_passes = coupling_passes_named(line.coupling_passes_text);
    config.settling_degree = settling_degree_named(line.settling_degree_text);
    config.results_format = results_format_named(line.format);
    if (!line.dt_text.empty()) options.dt = parse_quantity(line.dt_text, Dimension::time, "--dt", {0, 1, true, false}, "s");
    if (options.threads < 1 || options.threads > cores)
      throw InputError("--threads must lie in [1, " + std::to_string(cores) + "] (got " +
                       std::to_string(options.threads) + ")" +
                       (launched_ranks() > 1 ? "; the cores this rank may use: mpirun binds each rank, --bind-to none "
                                               "or --map-by slot:PE=N gives it more"
                                             : ""));
    options.external_pressure = parse_quantity(line.external_text, Dimension::pressure, "--external-pressure",
                                               {-100 * pascal_per_mmhg, 100 * pascal_per_mmhg}, "mmHg");
    config.sample_interval =
        parse_quantity(line.sample_text, Dimension::time, "--sample-interval", {0, 1e6, true, false}, "s");

    // A steady run over ranks of an HDF5 file: each rank but the lead reads the topology here
    // and its slice alone later (the lead reads the whole, to check it as the plain command
    // does and write the results).
    config.network_in_slices = line.steady && world_size() > 1 && line.pressure_at_texts.empty() && line.tracer_texts.empty() && !vtk &&
                               frames == 0 && network_in_hdf5;
    net = !config.network_in_slices || world_rank() == 0 ? read_network(config.network_name)
                                                         : read_network_topology(config.network_name);
    fix_pressures(net, line.pressure_at_texts, quiet);
    if (!vtk_min_text.empty()) {
      if (!vtk && frames == 0) throw InputError("--vtk-min-diameter applies to --vtk and --frames only");
      config.vtk_keep = vtk_vessels(net, vtk_min_text, quiet);
    }
    if ((vtk || frames > 0) && net.x.empty())
      throw InputError("--vtk and --frames need node coordinates (x, y, z) in the network file");
    config.red_cells = red_cells_named(line.red_cells);
    config.tracers = parse_tracers(line.tracer_texts, net);
  });
  if (line.steady) {
    run_steady(net, config, observer);
    return 0;
  }
  on_every_rank([&] {
    check_pulsatile(net, config);
    for (const auto& t : line.probe_texts) config.probes.push_back(parse_probe(t, net));
  });
  if (line.linear) {
    run_linear(net, config, observer);
    return 0;
  }
  return finish(run_pulsatile(std::move(net), config, observer), config);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Solve 1D pulsatile blood flow in a compliant vascular network (spectral/hp "
               "discontinuous Galerkin) and report flows, pressures and pulsatility. Under mpirun -np P a "
               "tree's run is split over P ranks by whole subtrees, its files those of one process "
               "(docs/scaling.md).",
               "hemosolve"};
  CommandLine line;
  const int cores = omp_get_num_procs();
  bind_options(app, line, cores);
  // Over MPI ranks every run (the steady state, with or without phase separation, the linear
  // periodic state, a pulsatile run on a tree); what a run cannot take over ranks it refuses
  // itself (solver/pulsatile_call.cpp, solver/linear_run.cpp).
  auto over_ranks = []() -> std::string { return ""; };
  return run_tool(app, argc, argv, hemosolve_words(), [&] { return run_command_line(line, cores); }, over_ranks);
}
