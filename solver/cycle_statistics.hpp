// Per-vessel statistics over one cardiac cycle, sampled every few steps:
// - at each vessel's centre: mean, systolic and diastolic pressure, pulsatility index, mean
//   wall shear stress (the paper's eq. WSS) and Reynolds number;
// - over the vessel: mean flow (its mode-0 coefficients);
// - at both ends of a 1D vessel: one Fourier coefficient of pressure and velocity, whose
//   phase lag along the vessel gives the measured pulse wave speeds (NaN in 0D vessels,
//   where no wave travels);
// and the cycle-to-cycle change that decides when the solution is periodic.
#pragma once

#include <array>
#include <cmath>
#include <complex>
#include <cstdint>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#include "pulse/pulse_solver.hpp"

namespace hemotree {

struct VesselCycle {
  double mean_flow = 0, mean_pressure = 0;
  double systolic_pressure = 0, diastolic_pressure = 0;
  double peak_flow = 0, least_flow = 0;  // largest and smallest flow at the centre
  double mean_wss = 0;   // [Pa]
  double reynolds = 0;   // rho u D / mu, cycle mean
  double pulsatility_index() const {
    return (systolic_pressure - diastolic_pressure) / mean_pressure;
  }
};

// Wall shear stress of the axisymmetric profile of the momentum-flux coefficient alpha,
// u(r) ~ 1 - (r/R)^zeta with alpha = (zeta + 2)/(zeta + 1): tau = mu u alpha / ((alpha - 1) R),
// 4 mu u / R for Poiseuille (alpha = 4/3).
double wall_shear_stress(double viscosity, double mean_velocity, double radius, double alpha);

// The phase velocity omega dx / arg(z0 conj(z1)) of a wave whose Fourier coefficients at
// two points dx apart are z0 (upstream) and z1; NaN unless the lag lies in (0, pi).
double phase_velocity(std::complex<double> z0, std::complex<double> z1, double omega, double dx);

// A vessel's measured pulse wave speeds: the phase velocity omega L / (phase lag from its
// inlet end to its outlet end) of its pressure and its velocity at the analysis frequency
// [m/s]; NaN where the lag is not positive (standing or backward waves) or no wave travels.
struct WaveSpeeds {
  double pressure = std::numeric_limits<double>::quiet_NaN(), velocity = std::numeric_limits<double>::quiet_NaN();
};

// A vessel's cycle results as a row of numbers, as a checkpoint holds them and a run over
// ranks gathers them: VesselCycle's eight in their order, then the wave speeds (NaN where
// none).
constexpr std::size_t cycle_row_width = 10;
std::array<double, cycle_row_width> cycle_row(const VesselCycle& c, const WaveSpeeds& w);
inline VesselCycle row_cycle(const double* row) {
  return {row[0], row[1], row[2], row[3], row[4], row[5], row[6], row[7]};
}
inline WaveSpeeds row_wave_speeds(const double* row) { return {row[8], row[9]}; }

struct CycleSummary {
  std::vector<VesselCycle> vessels;
  // The wave speeds where a wave travels (the 1D vessels: a few hundred of millions), by
  // vessel index, increasing; wave_speeds(v) gives NaN for every other vessel.
  std::vector<std::pair<std::size_t, WaveSpeeds>> waves;
  WaveSpeeds wave_speeds(std::size_t vessel) const;
  // Mean flow in through the boundaries that count as entering (the inlet; flows into the
  // network, pressures whose steady flow enters) and out through the others (outlets,
  // prescribed outflows), from the volume fluxes the solver exchanged there: over a periodic
  // cycle the compliances store nothing, and they agree.
  double inlet_mean_flow = 0, outlets_mean_flow = 0;
  // Whether what came in is more than round-off: over a stepped cycle, more than the floor
  // of exchange_scale (a millionth of the network's volume); a solved flow, any. Where it is
  // not, there is no fraction of it to give (summary.json's mass_balance is null).
  bool inflow_measured = true;
  // Per boundary (PulseSolver::boundary_list), the mean flow in through it [m^3/s].
  std::vector<double> boundary_mean_flow;
  // The change of the blood volume in the vessels over the cycle [m^3], and the scheme's
  // mass balance: (in - out - change) / exchange_scale(in, out, volume), round-off and the
  // junctions' tolerance.
  double volume_change = 0, conservation_error = 0;
};

// What the mass balance is relative to: the volume that went in or out over the cycle [m^3],
// and where (almost) nothing did (zero boundary flows: a network at rest) a millionth of the
// network's volume, against which the stored volume's round-off (1e-16 of it) stays far below
// any tolerance: the balance is defined, and a run where nothing flows balances.
double exchange_scale(double in, double out, double network_volume);

class CycleStatistics {
 public:
  // analysis_frequency: the harmonic [Hz] at which the pulse wave speeds are measured, in
  // the solver's 1D vessels.
  CycleStatistics(const Network& net, const PulseSolver& solver, double analysis_frequency);
  // Marks the start of a cycle (after any compliance balance, which moves volume).
  void begin(const PulseSolver& solver);
  // Samples the solver's state at time t, standing for the `weight` seconds before it. The
  // last sample of a cycle is at the state close() sees.
  void sample(const PulseSolver& solver, double t, double weight);
  // Closes the cycle at the solver's state now: returns the statistics. Over ranks every
  // rank's own vessels' results, by entry, and on rank 0 the cycle's sums (in- and outflow,
  // boundaries, volume change, mass balance); solver/cycle_over_ranks.hpp takes the vessels'
  // to rank 0 (gather_cycle_rows, a block at a time; gather_cycle_vessels, whole).
  CycleSummary close(const PulseSolver& solver);
  // By entry (over ranks): each entry's vessel, close()'s order of the vessels' results.
  // Empty by vessel.
  std::vector<std::int32_t> entry_vessels(const PulseSolver& solver) const;

 private:
  const Network& net_;
  double omega_;
  Eigen::VectorXd boundary_start_;                               // at begin()
  double volume_start_ = 0;
  // Per vessel, the cycle's results as they are gathered: the means' fields hold their
  // sums until close() divides them by the duration, the extremes their extremes so far. The
  // sums become the results where they lie: no second per-vessel array at the cycle's end,
  // the run's largest moment (80 B a vessel on it).
  // By vessel alone; over ranks by entry on every rank, the lead too, its own size: its 0D
  // system's vessels in their order, then its 1D vessels (entry_vessels()), and close()'s
  // summary the same (the lead held the whole network's, 64 B a vessel, until 2026-12-07).
  std::vector<VesselCycle> sums_;
  bool by_entry_ = false;
  std::size_t lumped_entries_ = 0;  // the 0D system's vessels (its halo's and ghosts' too)
  // The sums at their starts (0, the extremes at -+infinity): made at a cycle's first sample
  // (or its close, if none), handed over as the results when it closes.
  void start_sums();
  // Per 1D vessel (one_d_, the solver's one_d_vessels(); a wave speed is measured only where a
  // wave travels, run_report.hpp): the Fourier sums at the ends, and each signal's first and
  // last sample of the cycle (a cycle that is not yet periodic drifts, and the drift's own
  // Fourier component is removed).
  std::vector<std::int32_t> one_d_;
  std::vector<std::complex<double>> p_in_, p_out_, u_in_, u_out_;
  std::vector<double> first_, last_;  // per 1D vessel: p_in, p_out, u_in, u_out
  double first_time_ = 0, last_time_ = 0;
  // Scratch: the 1D vessels' samples at the centre and the two ends.
  std::vector<double> area_, q_, p_, area_end_, q_end_, p_end_, area_out_, q_out_, p_out_end_;
  void record_ends(const PulseSolver& solver, std::vector<double>& values);  // p_in, p_out, u_in, u_out
  double duration_ = 0;
};

// The largest relative change of a vessel's mean pressure between two cycles, and where.
struct PeriodicityChange {
  double change = 0;
  std::size_t vessel = 0;
  // Takes a vessel's change, |current - previous| / |current|, where it is the largest yet
  // (the first such vessel in the order they come).
  void compare(std::size_t v, double previous, double current) {
    const double c = std::abs(current - previous) / std::abs(current);
    if (c > change) *this = {c, v};
  }
};
PeriodicityChange cycle_change(std::span<const double> previous_mean_pressure,
                               const std::vector<VesselCycle>& current);
// Each vessel's mean pressure of a cycle's results: what the periodicity test and the
// compliance balance take of them.
std::vector<double> mean_pressures(const std::vector<VesselCycle>& cycle);

}  // namespace hemotree
