#include "solver/linear_run.hpp"

#include "solver/results_files.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <complex>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <limits>
#include <numbers>
#include <span>
#include <vector>

#include "core/units.hpp"
#include "distributed/gather_rows.hpp"
#include "distributed/linear_periodic_over_ranks.hpp"
#include "distributed/network_cut.hpp"
#include "mpi/session.hpp"
#include "partition/partition.hpp"
#include "harmonic/linear_periodic.hpp"
#include "harmonic/trigonometric_extremes.hpp"
#include "physics/poiseuille.hpp"
#include "physics/womersley.hpp"
#include "solver/cycle_statistics.hpp"
#include "solver/output_folder.hpp"
#include "solver/probes.hpp"
#include "solver/run_report.hpp"
#include "solver/steady_run.hpp"
#include "steady/vessel_laws.hpp"

namespace hemotree {

namespace {

// Rows of probes.csv over one period (the extremes are the series' own:
// harmonic/trigonometric_extremes.hpp).
constexpr int samples_per_period = 256;

// A wave travels where the run's --model auto would keep the vessel 1D.
bool wave_travels(const VesselLine& line, const SolverOptions& options, double omega, double period) {
  const double c0 = 1 / std::sqrt(line.inertance * line.compliance);
  const double rc = line.resistance * line.length * line.compliance * line.length;
  return !options.moves_in_phase(line.length / c0, omega * rc, period);
}

struct LinearCycle {
  CycleSummary cycle;
  std::vector<std::uint8_t> wave_travels;
  std::vector<double> womersley, pwv_elastic, pwv_theory;
};

// The mean pressure at a vessel's middle: on the compliant tube's steady profile between its
// nodes' means (the lumen narrows along the pressure drop, so the middle lies below their
// mean: physics/poiseuille.hpp, steady_profile_pressure, as a 0D vessel reports it and a 1D
// vessel's friction holds it), with the mean's second-order shift along it. A tapered
// vessel's profile is its nodes' line, as before.
double middle_mean_pressure(const Network& net, const TubeLaw& law, const ViscosityTable& viscosity, double k_friction,
                            const LinearPeriodic& periodic, std::size_t v) {
  const double shifted = periodic.mean_pressure_at(v, 0.5);
  if (net.is_tapered(v)) return shifted;
  const double pa = periodic.mean_node_pressure(static_cast<std::size_t>(net.from[v]));
  const double pb = periodic.mean_node_pressure(static_cast<std::size_t>(net.to[v]));
  auto capacity = [&](double p) {
    const double area = law.area(p);
    return flow_capacity(area, viscosity(area), k_friction);
  };
  return shifted + steady_profile_pressure(pa, pb, capacity(pa), capacity(pb), 0.5) - 0.5 * (pa + pb);
}

// One vessel's results, of those the linear periodic state holds.
struct LinearVessel {
  VesselCycle cycle;
  bool wave_travels = false;
  double womersley = 0, pwv_elastic = 0, pwv_theory = 0;
};

class LinearVessels {
 public:
  LinearVessels(const Network& net, const Blood& blood, const ViscosityTable& viscosity, std::span<const TubeLaw> laws,
                const LinearPeriodic& periodic, const SolverOptions& options, double analysis)
      : net_(net), blood_(blood), viscosity_(viscosity), laws_(laws), periodic_(periodic), options_(options),
        analysis_(analysis), k_friction_(friction_coefficient(blood.alpha)), extremes_(periodic.harmonics()),
        analysed_(static_cast<int>(std::lround(analysis * periodic.period()))) {}

  // Per thread: the harmonics at a vessel's middle and the extremes' samples.
  struct Scratch {
    std::vector<std::complex<double>> p, q;
    std::vector<double> samples;
  };
  LinearVessel operator()(std::size_t v, Scratch& s) const {
    const int harmonics = periodic_.harmonics();
    const double period = periodic_.period(), omega = 2 * std::numbers::pi / period;
    s.p.resize(static_cast<std::size_t>(harmonics));
    s.q.resize(s.p.size());
    const VesselLine& line = periodic_.line(v);
    LinearVessel out;
    VesselCycle& c = out.cycle;
    const double area = blood_.density / line.inertance, radius = std::sqrt(area / std::numbers::pi);
    const double mu = viscosity_(area);
    for (int k = 1; k <= harmonics; ++k) {
      const VesselLine::Point middle = periodic_.middle(k, v);
      s.p[static_cast<std::size_t>(k - 1)] = middle.pressure;
      s.q[static_cast<std::size_t>(k - 1)] = middle.flow;
    }
    const Extremes dp = extremes_(s.p, s.samples), dq = extremes_(s.q, s.samples);
    c.mean_flow = periodic_.mean_flow(v);
    c.mean_pressure = middle_mean_pressure(net_, laws_[v], viscosity_, k_friction_, periodic_, v);
    c.systolic_pressure = c.mean_pressure + dp.greatest;
    c.diastolic_pressure = c.mean_pressure + dp.least;
    c.peak_flow = c.mean_flow + dq.greatest;
    c.least_flow = c.mean_flow + dq.least;
    const double u = c.mean_flow / area;
    c.mean_wss = wall_shear_stress(mu, u, radius, blood_.alpha);  // linear in u: its cycle mean
    c.reynolds = blood_.density * u * 2 * radius / mu;
    const double c0 = 1 / std::sqrt(line.inertance * line.compliance);
    out.wave_travels = wave_travels(line, options_, omega, period);
    const double w = 2 * std::numbers::pi * analysis_;
    out.pwv_elastic = c0;
    out.womersley = womersley_number(2 * radius, blood_.density, mu, w);
    out.pwv_theory = womersley_wave(c0, out.womersley, w).phase_velocity;
    return out;
  }
  // The measured wave speeds where the report gives them: where a wave travels, at the
  // analysed harmonic when it is one of those solved.
  bool measures_waves() const { return analysed_ >= 1 && analysed_ <= periodic_.harmonics(); }
  WaveSpeeds wave_speeds(std::size_t v) const {
    const auto points = periodic_.ends_and_middle(analysed_, v);
    const double w = periodic_.omega(analysed_), length = periodic_.line(v).length;
    return {phase_velocity(points[0].pressure, points[2].pressure, w, length),
            phase_velocity(points[0].flow, points[2].flow, w, length)};
  }

 private:
  const Network& net_;
  const Blood& blood_;
  const ViscosityTable& viscosity_;
  std::span<const TubeLaw> laws_;
  const LinearPeriodic& periodic_;
  const SolverOptions& options_;
  double analysis_, k_friction_;
  TrigonometricExtremes extremes_;
  int analysed_;
};

LinearCycle linear_cycle(const Network& net, const LinearVessels& results, const LinearPeriodic& periodic, int threads) {
  const std::size_t n = net.vessel_count();
  LinearCycle out;
  out.cycle.vessels.resize(n);  // every number of each is set below
  add_boundary_flows(net, SteadyFlow{periodic.mean_flow(), periodic.mean_node_pressure(), 0.0}, out.cycle);
  out.wave_travels.assign(n, 0);
  out.womersley.assign(n, 0.0);
  out.pwv_elastic.assign(n, 0.0);
  out.pwv_theory.assign(n, 0.0);
  const auto vessels = static_cast<std::int64_t>(n);
#pragma omp parallel num_threads(threads) if (threads > 1)
  {
    LinearVessels::Scratch scratch;
#pragma omp for schedule(dynamic, 1024)
    for (std::int64_t i = 0; i < vessels; ++i) {
      const auto v = static_cast<std::size_t>(i);
      const LinearVessel r = results(v, scratch);
      out.cycle.vessels[v] = r.cycle;
      out.wave_travels[v] = r.wave_travels;
      out.womersley[v] = r.womersley;
      out.pwv_elastic[v] = r.pwv_elastic;
      out.pwv_theory[v] = r.pwv_theory;
    }
  }
  if (results.measures_waves())
    for (std::size_t v = 0; v < n; ++v)
      if (out.wave_travels[v]) out.cycle.waves.emplace_back(v, results.wave_speeds(v));
  return out;
}

ProbeRecorder linear_probes(const std::vector<TubeLaw>& laws, const LinearPeriodic& periodic,
                            const std::vector<Probe>& probes) {
  ProbeRecorder recorder(probes);
  for (int m = 0; m <= samples_per_period; ++m) {
    const double t = periodic.period() * m / samples_per_period;
    recorder.add_row(t, [&](const Probe& probe) {
      const double p = periodic.pressure_at(probe.vessel, probe.x, t), q = periodic.flow_at(probe.vessel, probe.x, t);
      const double a = laws[probe.vessel].area(p);
      return ProbeRecorder::Values{p, q, a};
    });
  }
  return recorder;
}

// The linear periodic state's results: the table's numbers, the probes' period, the mean
// flows and node pressures (the boundaries'), the harmonics solved.
struct LinearOutcome {
  LinearCycle linear;
  ProbeRecorder probes;
  SteadyFlow mean;
  int harmonics = 0;
  std::string partition;  // over ranks: the partition and the exchanges, in one line
};

LinearOutcome linear_here(const Network& net, const Blood& blood, const ViscosityTable& viscosity,
                          const std::vector<TubeLaw>& laws, const SolverOptions& options, double analysis,
                          const std::function<bool(const VesselLine&)>& travels, const std::vector<Probe>& probes) {
  const LinearPeriodic periodic =
      solve_linear_periodic(net, blood, laws, viscosity, options.periodic_harmonics, options.threads, travels);
  return {linear_cycle(net, LinearVessels(net, blood, viscosity, laws, periodic, options, analysis), periodic, options.threads),
          linear_probes(laws, periodic, probes), SteadyFlow{periodic.mean_flow(), periodic.mean_node_pressure(), 0.0},
          periodic.harmonics(), ""};
}

// Over the MPI session's ranks (distributed/linear_periodic_over_ranks.hpp): each rank the
// results of its vessels, nodes and probes, gathered on rank 0 in the whole network's order,
// each number the one-process run's. Rank 0's outcome; the others' empty.
LinearOutcome linear_over_ranks(const Network& net, const Blood& blood, const ViscosityTable& viscosity,
                                const std::vector<TubeLaw>& laws, const SolverOptions& options, double analysis,
                                const std::function<bool(const VesselLine&)>& travels, const std::vector<Probe>& probes) {
  const int ranks = world_size(), rank = world_rank();
  const std::size_t n = net.vessel_count();
  const LinearPeriodicOverRanks mine =
      solve_linear_periodic_over_ranks(net, blood, laws, viscosity, options.periodic_harmonics, options.threads, travels);
  const LinearPeriodic& periodic = mine.periodic;
  const LinearVessels results(net, blood, viscosity, laws, periodic, options, analysis);
  // Per vessel: its cycle's eight numbers, whether a wave travels, its Womersley number and
  // wave speeds of theory, and the two measured where a wave travels (else NaN).
  constexpr std::size_t width = 14;
  std::vector<double> vessel_rows(width * mine.vessels.size());
  const auto count = static_cast<std::int64_t>(mine.vessels.size());
#pragma omp parallel num_threads(options.threads) if (options.threads > 1)
  {
    LinearVessels::Scratch scratch;
#pragma omp for schedule(dynamic, 1024)
    for (std::int64_t i = 0; i < count; ++i) {
      const auto v = static_cast<std::size_t>(mine.vessels[static_cast<std::size_t>(i)]);
      const LinearVessel r = results(v, scratch);
      const WaveSpeeds speeds = r.wave_travels && results.measures_waves() ? results.wave_speeds(v) : WaveSpeeds{};
      const VesselCycle& c = r.cycle;
      const double row[width] = {c.mean_flow,   c.mean_pressure,  c.systolic_pressure, c.diastolic_pressure,
                                 c.peak_flow,   c.least_flow,     c.mean_wss,          c.reynolds,
                                 r.wave_travels ? 1.0 : 0.0, r.womersley, r.pwv_elastic, r.pwv_theory,
                                 speeds.pressure, speeds.velocity};
      std::copy(row, row + width, vessel_rows.begin() + static_cast<std::ptrdiff_t>(width) * i);
    }
  }
  std::vector<double> node_rows;
  for (const std::int32_t node : mine.nodes) node_rows.push_back(periodic.mean_node_pressure(static_cast<std::size_t>(node)));
  // Each probe's period, by the rank that holds its vessel.
  const std::vector<std::int32_t>& vessel_rank = mine.vessel_rank;
  constexpr std::size_t probe_width = 3 * (samples_per_period + 1);
  std::vector<double> probe_rows;
  for (const Probe& probe : probes) {
    if (vessel_rank[probe.vessel] != rank) continue;
    for (int m = 0; m <= samples_per_period; ++m) {
      const double t = periodic.period() * m / samples_per_period;
      const double p = periodic.pressure_at(probe.vessel, probe.x, t), q = periodic.flow_at(probe.vessel, probe.x, t);
      probe_rows.insert(probe_rows.end(), {p, q, laws[probe.vessel].area(p)});
    }
  }
  // Every rank's lists, on rank 0: its vessels, its nodes, its probes.
  const std::vector<std::vector<std::int32_t>>& vessels_of = mine.vessels_of;
  const std::vector<std::vector<std::int32_t>>& nodes_of = mine.nodes_of;
  std::vector<std::vector<std::int32_t>> probes_of;
  if (rank == 0) {
    probes_of.resize(static_cast<std::size_t>(ranks));
    for (std::size_t j = 0; j < probes.size(); ++j)
      probes_of[static_cast<std::size_t>(vessel_rank[probes[j].vessel])].push_back(static_cast<std::int32_t>(j));
  }
  LinearOutcome out{{}, ProbeRecorder(probes), {}, periodic.harmonics(), describe(mine.partition) + "; " + mine.solver};
  LinearCycle& linear = out.linear;
  std::vector<WaveSpeeds> speeds;
  if (rank == 0) {
    linear.cycle.vessels.resize(n);
    linear.wave_travels.assign(n, 0);
    linear.womersley.assign(n, 0.0);
    linear.pwv_elastic.assign(n, 0.0);
    linear.pwv_theory.assign(n, 0.0);
    out.mean.flow.resize(n);
    out.mean.node_pressure.resize(net.node_count());
    speeds.resize(n);
  }
  gather_rows(vessel_rows, width, vessels_of, n, [&](std::int32_t vessel, const double* row) {
    const auto v = static_cast<std::size_t>(vessel);
    linear.cycle.vessels[v] = {row[0], row[1], row[2], row[3], row[4], row[5], row[6], row[7]};
    linear.wave_travels[v] = row[8] != 0;
    linear.womersley[v] = row[9];
    linear.pwv_elastic[v] = row[10];
    linear.pwv_theory[v] = row[11];
    speeds[v] = {row[12], row[13]};
    out.mean.flow[v] = row[0];
  });
  std::vector<double>().swap(vessel_rows);
  gather_rows(node_rows, 1, nodes_of, net.node_count(),
              [&](std::int32_t node, const double* row) { out.mean.node_pressure[static_cast<std::size_t>(node)] = row[0]; });
  std::vector<double> all_probes(rank == 0 ? probe_width * probes.size() : 0);
  gather_rows(probe_rows, probe_width, probes_of, probes.size(), [&](std::int32_t j, const double* row) {
    std::copy(row, row + probe_width, all_probes.begin() + static_cast<std::ptrdiff_t>(probe_width) * j);
  });
  if (rank != 0) return out;
  if (results.measures_waves())
    for (std::size_t v = 0; v < n; ++v)
      if (linear.wave_travels[v]) linear.cycle.waves.emplace_back(v, speeds[v]);
  add_boundary_flows(net, out.mean, linear.cycle);
  for (int m = 0; m <= samples_per_period; ++m) {
    const double t = periodic.period() * m / samples_per_period;
    std::size_t j = 0;
    out.probes.add_row(t, [&](const Probe&) {
      const double* x = all_probes.data() + probe_width * j++ + 3 * static_cast<std::size_t>(m);
      return ProbeRecorder::Values{x[0], x[1], x[2]};
    });
  }
  return out;
}

}  // namespace

void run_linear(const Network& net, const RunConfiguration& config, RunObserver& observer) {
  const SolverOptions& options = config.solver;
  Blood blood = net.blood.value_or(Blood{});
  if (options.rheology_override >= 0) blood.rheology = static_cast<Rheology>(options.rheology_override);
  // Over MPI ranks rank 0 alone takes the folder and writes; its refusal is every rank's
  // before any of them solves.
  std::optional<OutputFolder> taken;
  on_lead_rank([&] { taken.emplace(config.out_dir); });
  const auto started = std::chrono::steady_clock::now();
  // What each rank sets up alone (a vessel's wall refused, say): its failure every rank's.
  std::optional<ViscosityTable> viscosity_table;
  std::vector<TubeLaw> laws;
  Waveform driving;
  on_every_rank([&] {
    viscosity_table.emplace(blood);
    laws = vessel_laws(net, blood, options.external_pressure, options.thick_wall_ratio);
    driving = driving_waveform(net);
  });
  const ViscosityTable& viscosity = *viscosity_table;
  const double analysis = analysis_frequency(driving), omega = 2 * std::numbers::pi / driving.period;
  // The mean moves by its second-order shift, forced where a run's --model auto keeps a vessel 1D.
  const std::function<bool(const VesselLine&)> travels = [&](const VesselLine& line) {
    return wave_travels(line, options, omega, driving.period);
  };
  const bool over_ranks = world_size() > 1;
  const LinearOutcome outcome = over_ranks
                                    ? linear_over_ranks(net, blood, viscosity, laws, options, analysis, travels, config.probes)
                                    : linear_here(net, blood, viscosity, laws, options, analysis, travels, config.probes);
  if (over_ranks) {
    if (world_rank() != 0) return;
    leave_collectives();  // the others have finished: a failure of the writing is rank 0's alone
    observer.note(outcome.partition);
  }
  const LinearCycle& linear = outcome.linear;
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();

  const std::size_t n = net.vessel_count();
  VesselTable results = cycle_table(net, linear.cycle, std::vector<std::uint8_t>(n, 0), {"linear"},
                                    std::vector<std::int64_t>(n, VesselTable::null_integer), linear.wave_travels);
  results.add_number_view("womersley", linear.womersley);
  results.add_number_view("pwv_elastic", linear.pwv_elastic);
  results.add_number_view("pwv_theory", linear.pwv_theory);
  nlohmann::json run_info = {{"tool", "hemosolve"},
                             {"version", HEMOTREE_VERSION},
                             {"network", config.network_name},
                             {"mode", "linear"},
                             {"model", "linear"},
                             {"harmonics", outcome.harmonics},
                             {"vessels_1d", 0},
                             {"vessels_0d", 0},
                             {"rheology", to_string(blood.rheology)},
                             {"red_cells", "fixed"},
                             {"period", driving.period},
                             {"pulse_frequency", pulse_frequency(driving)},
                             {"analysis_frequency", analysis},
                             {"status", "complete"},
                             {"cycles", 0},
                             {"wall_time", wall}};
  run_info["statistics"] = group_statistics(net, results, options.threads);
  OutputFolder& folder = *taken;
  folder.open();
  const std::filesystem::path dir = folder.staging();
  write_results(dir, {run_info, results, linear.cycle, boundary_results(net, outcome.mean), &outcome.probes, options.threads},
                config.results_format);
  if (config.vtk) write_results_vtk(dir / "results.vtp", net, results, config.vtk_keep);
  folder.publish();
  observer.note("linear periodic state of " + std::to_string(n) + " vessels (" + std::to_string(outcome.harmonics) +
                " harmonics) in " + format_quantity(wall, "s") + "; results in " + config.out_dir);
}

}  // namespace hemotree
