// hemosolve: pulsatile flow in a compliant network by the spectral/hp DG method.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli/errors.hpp"
#include "cli/tool.hpp"
#include "cli/units.hpp"
#include "formats/network_io.hpp"
#include "solver/cycle_statistics.hpp"
#include "formats/vtk_series.hpp"
#include "solver/probes.hpp"
#include "solver/pulse_solver.hpp"
#include "solver/run_report.hpp"
#include "solver/solution_breakdown.hpp"

using namespace hemotree;

namespace {

std::string number(double v) {
  char text[32];
  return std::string(text, format_real(text, v));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Solve 1D pulsatile blood flow in a compliant vascular network (spectral/hp "
               "discontinuous Galerkin) and report flows, pressures and pulsatility.",
               "hemosolve"};
  std::string input, out_dir, rheology, scheme = "etd2", start = "steady", dt_text, sample_text = "1ms",
              external_text = "10mmHg", degree_text = "auto";
  int cycles = 1, max_cycles = 50;
  double periodic_tol = 0;
  std::vector<std::string> probe_texts;
  bool quiet = false, vtk = false, balance = true;
  int frames = 0;
  SolverOptions options;
  app.add_option("network", input, "network file (vnet JSON), - for standard input")->required();
  app.add_option("--out", out_dir, "folder for summary.json and probes.csv")->required();
  app.add_option("--cycles", cycles, "cardiac cycles to run")->capture_default_str();
  app.add_option("--until-periodic", periodic_tol,
                 "run until every vessel's mean pressure changes less than this from one cycle to the next");
  app.add_option("--max-cycles", max_cycles, "upper bound for --until-periodic")->capture_default_str();
  app.add_option("--probe", probe_texts, "record p, Q, A, u at vessel ID, fraction x along it (ID[:x], x 0.5 by default)");
  app.add_option("--sample-interval", sample_text, "time between probe samples")->capture_default_str();
  app.add_option("--degree", degree_text,
                 "polynomial degree p in every vessel, or auto: per vessel, --low-degree in vessels much "
                 "shorter than the pulse's wavelength (raised up to --raise-degree where the time step "
                 "allows), --high-degree elsewhere")
      ->capture_default_str();
  app.add_option("--low-degree", options.degree_rule.low, "auto: degree of acoustically short vessels")
      ->capture_default_str();
  app.add_option("--raise-degree", options.degree_rule.raise_to,
                 "auto: the most a short vessel is raised to at no cost in time step")
      ->capture_default_str();
  app.add_option("--high-degree", options.degree_rule.high, "auto: degree of the other vessels")
      ->capture_default_str();
  app.add_option("--linear-error", options.degree_rule.linear_error,
                 "auto: a short vessel whose steady pressure profile departs further than this from a "
                 "line (relative; docs/solver.md) takes degree 2")
      ->capture_default_str();
  app.add_option("--elements", options.elements, "elements per vessel")->capture_default_str();
  app.add_option("--dt", dt_text, "time step (default: from the CFL and friction limits)");
  app.add_option("--cfl", options.cfl, "fraction of the wave-speed (Courant) stability limit of the degree and scheme")->capture_default_str();
  app.add_option("--scheme", scheme, "time scheme: etd2 (Adams-Bashforth 2 with exact friction), ab2 (the paper's) or rk4")->capture_default_str();
  app.add_option("--rheology", rheology, "pries or newtonian (default: the network's blood)");
  app.add_option("--start", start, "initial state: steady (Poiseuille solution) or rest")->capture_default_str();
  app.add_option("--external-pressure", external_text, "interstitial pressure for the wall laws")->capture_default_str();
  app.add_option("--thick-wall-ratio", options.thick_wall_ratio, "h/D above which a wall is thick")->capture_default_str();
  app.add_option("--threads", options.threads, "threads over elements (use the idle cores; results agree to round-off)")
      ->capture_default_str();
  app.add_flag("--vtk", vtk, "also write the network with every per-vessel result as VTK (results.vtp, for ParaView)");
  app.add_option("--frames", frames,
                 "write N frames of the last cycle (p, Q, A, u per vessel) as a ParaView time series "
                 "(frames/frames.pvd)");
  app.add_flag("--balance-compliances,!--no-balance-compliances", balance,
               "at each cycle end, move the network's compliances (vessels and RCR capacitors) to where "
               "their mean filling over the cycle says the periodic state lies (docs/solver.md; on by default)");
  app.add_flag("--quiet", quiet, "no progress line");
  app.set_version_flag("--version", std::string("hemosolve ") + HEMOTREE_VERSION);

  return run_tool(app, argc, argv, [&] {
    if (cycles < 1) throw InputError("--cycles must be at least 1");
    if (scheme == "rk4") options.scheme = TimeScheme::runge_kutta4;
    else if (scheme == "ab2") options.scheme = TimeScheme::adams_bashforth2;
    else if (scheme == "etd2") options.scheme = TimeScheme::exponential_ab2;
    else throw InputError("--scheme must be etd2, ab2 or rk4");
    if (start == "rest") options.steady_start = false;
    else if (start != "steady") throw InputError("--start must be steady or rest");
    if (!rheology.empty()) {
      if (rheology == "pries") options.rheology_override = static_cast<int>(Rheology::pries);
      else if (rheology == "newtonian") options.rheology_override = static_cast<int>(Rheology::newtonian);
      else throw InputError("--rheology must be pries or newtonian");
    }
    if (!dt_text.empty()) {
      options.dt = parse_quantity(dt_text, Dimension::time, "--dt");
      if (!(options.dt > 0)) throw InputError("--dt must be positive");
    }
    if (!(options.cfl > 0)) throw InputError("--cfl must be positive");
    if (degree_text != "auto") {
      std::size_t used = 0;
      try {
        options.degree = std::stoi(degree_text, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used == 0 || used != degree_text.size() || options.degree < 0)
        throw InputError("--degree must be auto or a whole number from 0 to 30");
    }
    for (const int p : {options.degree_rule.low, options.degree_rule.raise_to, options.degree_rule.high})
      if (p < 0 || p > 30) throw InputError("--low-degree, --raise-degree and --high-degree must lie in 0..30");
    if (!(options.degree_rule.linear_error >= 0)) throw InputError("--linear-error must be zero or positive");
    options.external_pressure = parse_quantity(external_text, Dimension::pressure, "--external-pressure");
    const double sample_interval = parse_quantity(sample_text, Dimension::time, "--sample-interval");

    if (frames < 0) throw InputError("--frames must be positive");
    const Network net = read_network(input);
    if ((vtk || frames > 0) && net.x.empty())
      throw InputError("--vtk and --frames need node coordinates (x, y, z) in the network file");
    std::vector<Probe> probe_list;
    for (const auto& t : probe_texts) probe_list.push_back(parse_probe(t, net));
    PulseSolver run(net, options);
    const double period = net.inlet->waveform.period;
    const auto steps_per_cycle = static_cast<std::size_t>(std::ceil(period / run.dt() - 1e-9));
    const double dt = period / static_cast<double>(steps_per_cycle);  // a whole number per cycle
    const std::string dt_reason = run.dt_reason();
    run.set_time_step(dt);  // slightly smaller, so that cycles end exactly on a step
    std::map<int, std::size_t> degrees;  // elements per degree
    for (std::size_t v = 0; v < net.vessel_count(); ++v) degrees[run.degree(v)] += static_cast<std::size_t>(options.elements);
    std::string degree_list;
    for (const auto& [p, count] : degrees)
      degree_list += (degree_list.empty() ? "" : ", ") + std::to_string(count) + " of degree " + std::to_string(p);
    if (!quiet)
      note("time step " + number(dt) + " s (" + dt_reason + "), " + std::to_string(steps_per_cycle) +
           " steps per cycle, " + std::to_string(run.element_count()) + " elements: " + degree_list);

    std::filesystem::path dir(out_dir);
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) throw IoError("cannot create " + out_dir + ": " + ec.message());

    ProbeRecorder probes(std::move(probe_list));
    const auto sample_every = std::max<std::size_t>(1, static_cast<std::size_t>(std::llround(sample_interval / dt)));
    const Waveform& pulse = net.inlet->waveform;
    const double frequency = analysis_frequency(pulse);
    std::vector<std::size_t> outlet_vessels;
    for (const Outlet& o : net.outlets) outlet_vessels.push_back(static_cast<std::size_t>(o.vessel));
    CycleStatistics stats(net, frequency, static_cast<std::size_t>(net.index_of(net.inlet->vessel)), outlet_vessels);
    // Statistics every 1e-4 of a period (or every step if that is longer): means and extrema
    // of the smooth pulse are then exact to ~1e-7, at a few per cent of the run's time.
    const auto stats_every = std::max<std::size_t>(1, static_cast<std::size_t>(1e-4 * period / dt));
    CycleSummary last, previous;
    nlohmann::json results;
    auto report = [&](const nlohmann::json& info) {
      results = vessel_results(net, run, last, frequency);
      write_summary(dir / "summary.json", info, results, last);
      if (vtk) write_results_vtk(dir / "results.vtp", net, results);
    };
    if (frames > 0) {
      std::filesystem::create_directories(dir / "frames", ec);
      if (ec) throw IoError("cannot create " + (dir / "frames").string() + ": " + ec.message());
    }
    PeriodicityChange change;
    int done = 0;
    int balances = 0;  // cycle ends at which the compliances moved
    const bool until_periodic = periodic_tol > 0;
    const int planned = until_periodic ? max_cycles : cycles;
    const bool show = !quiet && stderr_is_terminal();
    const auto started = std::chrono::steady_clock::now();
    nlohmann::json run_info = {{"tool", "hemosolve"}, {"version", HEMOTREE_VERSION},
                               {"network", input},
                               {"degree", options.degree == SolverOptions::automatic ? nlohmann::json("auto")
                                                                                     : nlohmann::json(options.degree)},
                               {"elements_per_vessel", options.elements}, {"scheme", scheme},
                               {"threads", options.threads},
                               {"rheology", to_string(run.blood().rheology)},
                               {"start", start}, {"balance_compliances", balance}, {"period", period},
                               {"pulse_frequency", pulse_frequency(pulse)}, {"analysis_frequency", frequency},
                               {"time_step", dt},
                               {"time_step_limit", dt_reason}};
    for (const auto& [p, count] : degrees) run_info["elements_of_degree"][std::to_string(p)] = count;
    try {
      probes.sample(run);
      if (balance) run.balance_compliances(period);
      for (; done < planned; ++done) {
        // Every cycle could be the last (--until-periodic): its frames replace the previous ones.
        std::optional<VtkTimeSeries> series;
        if (frames > 0) series.emplace(net, dir / "frames", "frames");
        std::size_t frames_written = 0;
        double sampled_until = run.time();
        for (std::size_t k = 0; k < steps_per_cycle; ++k) {
          run.step();
          if ((k + 1) % stats_every == 0 || k + 1 == steps_per_cycle) {
            stats.sample(run, run.time(), run.time() - sampled_until);
            sampled_until = run.time();
          }
          if (series && (k + 1) * static_cast<std::size_t>(frames) >= (frames_written + 1) * steps_per_cycle) {
            add_solution_frame(*series, run);
            ++frames_written;
          }
          if (run.steps() % sample_every == 0) probes.sample(run);
          if (show && k % 256 == 0) {
            const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
            const double rate = static_cast<double>(run.steps()) / std::max(elapsed, 1e-9);
            const double left = static_cast<double>(planned * steps_per_cycle - run.steps()) / rate;
            std::fprintf(stderr, "\rhemosolve: cycle %d/%d  t = %.4f s  %.0f steps/s  %.0f s left   ",
                         done + 1, planned, run.time(), rate, left);
          }
        }
        run.check_solution();
        previous = std::move(last);
        last = stats.close();
        if (series) series->finish();
        if (balance && run.balance_compliances(period) > 0) ++balances;
        if (!previous.vessels.empty()) change = cycle_change(previous.vessels, last.vessels);
        if (until_periodic && !previous.vessels.empty() && change.change < periodic_tol) {
          ++done;
          break;
        }
      }
    } catch (const SolutionBreakdown& e) {
      if (show) std::fprintf(stderr, "\r\033[K");
      run_info["status"] = "broken down";
      run_info["error"] = e.what();
      run_info["cycles"] = done;
      probes.write(dir / "probes.csv");
      if (!last.vessels.empty()) report(run_info);
      throw InputError(e.what());
    }
    if (show) std::fprintf(stderr, "\r\033[K");
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    run_info["status"] = until_periodic && !(change.change < periodic_tol) ? "not periodic" : "complete";
    run_info["cycles"] = done;
    run_info["steps"] = run.steps();
    run_info["compliance_balances"] = balances;
    run_info["wall_time"] = wall;
    if (!previous.vessels.empty()) {
      run_info["periodic_change"] = change.change;
      run_info["slowest_vessel"] = net.id[change.vessel];
    }
    probes.write(dir / "probes.csv");
    report(run_info);
    if (!quiet) {
      std::ostringstream m;
      m << done << " cycles in " << wall << " s";
      if (!previous.vessels.empty())
        m << "; last cycle-to-cycle change " << change.change << " (vessel " << net.id[change.vessel] << ")";
      m << "; results in " << out_dir;
      note(m.str());
    }
    if (until_periodic && !(change.change < periodic_tol))
      warn("not periodic within " + std::to_string(max_cycles) + " cycles (--max-cycles)");
    return 0;
  });
}
