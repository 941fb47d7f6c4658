#include "solver/cycle_statistics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/parallel_errors.hpp"
#include "solver/cycle_over_ranks.hpp"

namespace hemotree {

double wall_shear_stress(double viscosity, double mean_velocity, double radius, double alpha) {
  return viscosity * mean_velocity * alpha / ((alpha - 1) * radius);
}

double exchange_scale(double in, double out, double network_volume) {
  return std::max({std::abs(in), std::abs(out), 1e-6 * network_volume});  // (CycleSummary::inflow_measured's floor)
}

double phase_velocity(std::complex<double> z0, std::complex<double> z1, double omega, double dx) {
  // A wave exp(i(omega t - k x)) has z(x) ~ exp(-i k x): z0 conj(z1) = |.| exp(i k dx).
  const double lag = std::arg(z0 * std::conj(z1));
  if (!(lag > 0) || !(std::abs(z0) > 0) || !(std::abs(z1) > 0)) return std::numeric_limits<double>::quiet_NaN();
  return omega * dx / lag;
}

CycleStatistics::CycleStatistics(const Network& net, const PulseSolver& solver, double analysis_frequency)
    : net_(net), omega_(2 * std::numbers::pi * analysis_frequency),
      one_d_(solver.one_d_vessels()) {
  by_entry_ = solver.over_ranks();
  lumped_entries_ = solver.lumped().vessel_count();
  const std::size_t n = one_d_.size();
  for (auto* sums : {&p_in_, &p_out_, &u_in_, &u_out_}) sums->assign(n, 0.0);
  first_.assign(4 * n, 0.0);
  last_.assign(4 * n, 0.0);
  for (auto* scratch : {&area_, &q_, &p_, &area_end_, &q_end_, &p_end_, &area_out_, &q_out_, &p_out_end_})
    scratch->assign(n, 0.0);
}

void CycleStatistics::start_sums() {
  const std::size_t n = by_entry_ ? lumped_entries_ + one_d_.size() : net_.vessel_count();
  constexpr double infinity = std::numeric_limits<double>::infinity();
  VesselCycle start;
  start.systolic_pressure = start.peak_flow = -infinity;
  start.diastolic_pressure = start.least_flow = infinity;
  sums_.assign(n, start);
}

void CycleStatistics::begin(const PulseSolver& solver) {
  // Over ranks, rank 0's: the whole run's (solver/cycle_over_ranks.hpp).
  const bool over_ranks = solver.over_ranks();
  boundary_start_ = over_ranks ? boundary_volumes_over_ranks(solver) : solver.boundary_volumes();
  volume_start_ = over_ranks ? network_volume_over_ranks(net_, solver) : solver.network_volume();
}

void CycleStatistics::sample(const PulseSolver& solver, double t, double weight) {
  // Rectangle rule: spectrally accurate for the means of periodic signals.
  const double rho = solver.blood().density, alpha = solver.blood().alpha;
  const int threads = solver.threads();
  const std::complex<double> phase = weight * std::polar(1.0, -omega_ * t);
  if (duration_ == 0) {
    if (sums_.empty()) start_sums();
    first_time_ = t;
    record_ends(solver, first_);
  }
  last_time_ = t;
  duration_ += weight;
  // At the centre: means, extrema, wall shear stress, Reynolds number; u, mu and the radius
  // from the sample (centre_values), then added to the vessel's sums (add_centre).
  struct CentreValues {
    double u, mu, radius;
  };
  auto centre_values = [&](std::size_t v, double a, double q) {
    return CentreValues{q / a, solver.viscosity(v, a), std::sqrt(a / std::numbers::pi)};
  };
  auto add_centre = [&](std::size_t entry, const CentreValues& c, double q, double p, double mean_q) {
    VesselCycle& s = sums_[entry];
    s.mean_flow += weight * mean_q;
    s.mean_pressure += weight * p;
    s.diastolic_pressure = std::min(s.diastolic_pressure, p);
    s.systolic_pressure = std::max(s.systolic_pressure, p);
    s.least_flow = std::min(s.least_flow, q);
    s.peak_flow = std::max(s.peak_flow, q);
    s.mean_wss += weight * wall_shear_stress(c.mu, c.u, c.radius, alpha);
    s.reynolds += weight * rho * c.u * 2 * c.radius / c.mu;
  };
  // The 1D vessels through the solver's arrays, three points each; at the ends the Fourier
  // sums of pressure and velocity.
  if (!one_d_.empty()) {
    solver.sample_one_d(0.5, area_, q_, p_);
    solver.sample_one_d(0.0, area_end_, q_end_, p_end_);
    solver.sample_one_d(1.0, area_out_, q_out_, p_out_end_);
    parallel_blocks(static_cast<std::int64_t>(one_d_.size()), threads, [&](std::int64_t first, std::int64_t last) {
      for (auto j = static_cast<std::size_t>(first); j < static_cast<std::size_t>(last); ++j) {
        const auto v = static_cast<std::size_t>(one_d_[j]);
        add_centre(by_entry_ ? lumped_entries_ + j : v, centre_values(v, area_[j], q_[j]), q_[j], p_[j], solver.mean_flow(v));
        p_in_[j] += phase * p_end_[j];
        u_in_[j] += phase * (q_end_[j] / area_end_[j]);
        p_out_[j] += phase * p_out_end_[j];
        u_out_[j] += phase * (q_out_[j] / area_out_[j]);
      }
    });
  }
  // The 0D vessels straight from their state, in one pass (their flow is one along the
  // vessel: its mean), a batch at a time, stage by stage.
  solver.lumped().for_each_centre_batch(
      [&](const LumpedVessels::CentreBatch& b) {
        CentreValues c[LumpedVessels::CentreBatch::width];
        for (std::size_t i = 0; i < b.n; ++i) c[i] = centre_values(b.vessel[i], b.area[i], b.flow[i]);
        for (std::size_t i = 0; i < b.n; ++i)
          add_centre(by_entry_ ? b.first + i : b.vessel[i], c[i], b.flow[i], b.pressure[i], b.flow[i]);
      },
      threads);
}

void CycleStatistics::record_ends(const PulseSolver& solver, std::vector<double>& values) {
  // Kept apart from sample(): the first and last samples alone (the drift between them),
  // rather than four more values written per vessel at every sample.
  if (one_d_.empty()) return;  // (over ranks, a share's)
  for (const int end : {0, 1}) {
    solver.sample_one_d(end, area_end_, q_end_, p_end_);
    for (std::size_t j = 0; j < one_d_.size(); ++j) {
      values[4 * j + static_cast<std::size_t>(end)] = p_end_[j];
      values[4 * j + 2 + static_cast<std::size_t>(end)] = q_end_[j] / area_end_[j];
    }
  }
}

CycleSummary CycleStatistics::close(const PulseSolver& solver) {
  CycleSummary summary;
  if (sums_.empty()) start_sums();  // no sample since the last close
  // In and out: each boundary's volume, in the boundaries' order, to "in" or "out" as it
  // counts (one sum per item whatever holds it: a run over ranks gathers the same numbers).
  const bool over_ranks = solver.over_ranks();
  const Eigen::VectorXd through =
      (over_ranks ? boundary_volumes_over_ranks(solver) : solver.boundary_volumes()) - boundary_start_;
  Eigen::Vector2d exchanged = Eigen::Vector2d::Zero();
  for (Eigen::Index i = 0; i < through.size(); ++i) {
    summary.boundary_mean_flow.push_back(through(i) / duration_);
    if (solver.boundary_entering()[static_cast<std::size_t>(i)]) exchanged(0) += through(i);
    else exchanged(1) -= through(i);
  }
  summary.inlet_mean_flow = exchanged(0) / duration_;
  summary.outlets_mean_flow = exchanged(1) / duration_;
  summary.inflow_measured = exchanged(0) > 1e-6 * volume_start_;
  summary.volume_change = (over_ranks ? network_volume_over_ranks(net_, solver) : solver.network_volume()) - volume_start_;
  summary.conservation_error =
      (exchanged(0) - exchanged(1) - summary.volume_change) / exchange_scale(exchanged(0), exchanged(1), volume_start_);
  if (duration_ > 0) record_ends(solver, last_);  // the state of the cycle's last sample
  begin(solver);  // the next cycle starts here unless begin() is called again
  std::vector<VesselCycle>& out = summary.vessels;
  out = std::move(sums_);  // the results where the sums lie; made again at the next cycle's first sample
  sums_ = {};
  // A linear drift s(t) = slope (t - t0) over the cycle [t0, t0 + T] has the Fourier sum
  // slope e^(-i omega t0) i T / omega at a harmonic omega = 2 pi k / T; it is taken out.
  const double slope_span = last_time_ > first_time_ ? duration_ / (last_time_ - first_time_) : 0.0;
  const std::complex<double> drift = std::polar(1.0, -omega_ * (last_time_ - duration_)) * std::complex<double>(0, 1 / omega_);
  auto detrended = [&](std::complex<double> sum, std::size_t k) { return sum - (last_[k] - first_[k]) * slope_span * drift; };
  for (std::size_t v = 0; v < out.size(); ++v) {
    VesselCycle& c = out[v];  // the extremes are already what they are
    c.mean_flow = c.mean_flow / duration_;
    c.mean_pressure = c.mean_pressure / duration_;
    c.mean_wss = c.mean_wss / duration_;
    c.reynolds = c.reynolds / duration_;
  }
  for (std::size_t j = 0; j < one_d_.size(); ++j) {
    const auto v = static_cast<std::size_t>(one_d_[j]);
    const double length = net_.length[v];
    summary.waves.emplace_back(
        v, WaveSpeeds{phase_velocity(detrended(p_in_[j], 4 * j), detrended(p_out_[j], 4 * j + 1), omega_, length),
                      phase_velocity(detrended(u_in_[j], 4 * j + 2), detrended(u_out_[j], 4 * j + 3), omega_, length)});
    p_in_[j] = p_out_[j] = u_in_[j] = u_out_[j] = 0;
  }
  std::ranges::sort(summary.waves, {}, &std::pair<std::size_t, WaveSpeeds>::first);
  duration_ = 0;
  return summary;
}

std::vector<std::int32_t> CycleStatistics::entry_vessels(const PulseSolver& solver) const {
  if (!by_entry_) return {};
  std::vector<std::int32_t> vessel(lumped_entries_ + one_d_.size());
  for (std::size_t e = 0; e < lumped_entries_; ++e) vessel[e] = static_cast<std::int32_t>(solver.lumped().network_vessel(e));
  std::copy(one_d_.begin(), one_d_.end(), vessel.begin() + static_cast<std::ptrdiff_t>(lumped_entries_));
  return vessel;
}

WaveSpeeds CycleSummary::wave_speeds(std::size_t vessel) const {
  const auto at = std::ranges::lower_bound(waves, vessel, {}, &std::pair<std::size_t, WaveSpeeds>::first);
  return at != waves.end() && at->first == vessel ? at->second : WaveSpeeds{};
}

PeriodicityChange cycle_change(std::span<const double> previous_mean_pressure,
                               const std::vector<VesselCycle>& current) {
  PeriodicityChange worst;
  for (std::size_t v = 0; v < current.size(); ++v) worst.compare(v, previous_mean_pressure[v], current[v].mean_pressure);
  return worst;
}

std::array<double, cycle_row_width> cycle_row(const VesselCycle& c, const WaveSpeeds& w) {
  return {c.mean_flow, c.mean_pressure, c.systolic_pressure, c.diastolic_pressure, c.peak_flow,
          c.least_flow, c.mean_wss, c.reynolds, w.pressure, w.velocity};
}

std::vector<double> mean_pressures(const std::vector<VesselCycle>& cycle) {
  std::vector<double> p(cycle.size());
  for (std::size_t v = 0; v < cycle.size(); ++v) p[v] = cycle[v].mean_pressure;
  return p;
}

}  // namespace hemotree
