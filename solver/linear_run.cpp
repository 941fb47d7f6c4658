#include "solver/linear_run.hpp"

#include "solver/results_files.hpp"

#include <array>
#include <chrono>
#include <cmath>
#include <complex>
#include <cstdint>
#include <limits>
#include <numbers>
#include <span>
#include <vector>

#include "core/units.hpp"
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
  const double pa = periodic.mean_node_pressure()[static_cast<std::size_t>(net.from[v])];
  const double pb = periodic.mean_node_pressure()[static_cast<std::size_t>(net.to[v])];
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

}  // namespace

void run_linear(const Network& net, const RunConfiguration& config, RunObserver& observer) {
  const SolverOptions& options = config.solver;
  Blood blood = net.blood.value_or(Blood{});
  if (options.rheology_override >= 0) blood.rheology = static_cast<Rheology>(options.rheology_override);
  OutputFolder folder(config.out_dir);
  const auto started = std::chrono::steady_clock::now();
  const ViscosityTable viscosity(blood);
  const std::vector<TubeLaw> laws = vessel_laws(net, blood, options.external_pressure, options.thick_wall_ratio);
  const Waveform driving = driving_waveform(net);
  const double analysis = analysis_frequency(driving), omega = 2 * std::numbers::pi / driving.period;
  // The mean moves by its second-order shift, forced where a run's --model auto keeps a vessel 1D.
  const LinearPeriodic periodic =
      solve_linear_periodic(net, blood, laws, viscosity, options.periodic_harmonics, options.threads,
                            [&](const VesselLine& line) { return wave_travels(line, options, omega, driving.period); });
  const LinearCycle linear =
      linear_cycle(net, LinearVessels(net, blood, viscosity, laws, periodic, options, analysis), periodic, options.threads);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();

  const std::size_t n = net.vessel_count();
  VesselTable results = cycle_table(net, linear.cycle, std::vector<std::uint8_t>(n, 0), {"linear"},
                                    std::vector<std::int64_t>(n, VesselTable::null_integer), linear.wave_travels);
  results.add_number("womersley", linear.womersley);
  results.add_number("pwv_elastic", linear.pwv_elastic);
  results.add_number("pwv_theory", linear.pwv_theory);
  nlohmann::json run_info = {{"tool", "hemosolve"},
                             {"version", HEMOTREE_VERSION},
                             {"network", config.network_name},
                             {"mode", "linear"},
                             {"model", "linear"},
                             {"harmonics", periodic.harmonics()},
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
  folder.open();
  const std::filesystem::path dir = folder.staging();
  const ProbeRecorder probes = linear_probes(laws, periodic, config.probes);
  write_results(dir,
                {run_info, results, linear.cycle,
                 boundary_results(net, SteadyFlow{periodic.mean_flow(), periodic.mean_node_pressure(), 0.0}), &probes,
                 options.threads},
                config.results_format);
  if (config.vtk) write_results_vtk(dir / "results.vtp", net, results, config.vtk_keep);
  folder.publish();
  observer.note("linear periodic state of " + std::to_string(n) + " vessels (" + std::to_string(periodic.harmonics()) +
                " harmonics) in " + format_quantity(wall, "s") + "; results in " + config.out_dir);
}

}  // namespace hemotree
