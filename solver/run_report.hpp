// What hemosolve reports of a run: every vessel's results over the last cycle (measured, and
// the linear wave theory beside them) in summary.json and as VTK cell data for ParaView, and
// snapshots of the solution as frames of a ParaView time series.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "formats/exports.hpp"
#include "formats/network.hpp"
#include "formats/vtk_series.hpp"
#include "solver/cycle_statistics.hpp"
#include "pulse/pulse_solver.hpp"
#include "solver/vessel_table.hpp"

namespace hemotree {

// The pulse's frequency [Hz]: 1 / systole for the half-sine (the paper's 3.33 Hz), 1 / period
// for a tabulated waveform. The wave speeds are measured and predicted at the harmonic of the
// period nearest to it (3 Hz for the paper's pulse in a 1 s cycle): only harmonics are free
// of leakage in a one-cycle Fourier sum.
double pulse_frequency(const Waveform& w);
double analysis_frequency(const Waveform& w);

// Linear theory for a vessel at angular frequency omega: the Womersley number of its
// reference lumen (viscosity at that diameter), the elastic wave speed c0 of its reference
// state, and the Womersley phase velocity at that c0 and W (the paper's eq. wavespeedWomersley);
// a tapered vessel's at its middle.
struct WaveTheory {
  double womersley = 0, pwv_elastic = 0, pwv_theory = 0;
};
WaveTheory wave_theory(const PulseSolver& solver, const Network& net, std::size_t vessel, double omega);

// The columns every run reports, one row per vessel in the network's order: id, geometry,
// class, the vessel's model (a label per vessel: model_labels[model[v]]) and degree (null
// where none), and the cycle's statistics. The table views the network's columns and the
// cycle's records: both must outlive it.
// wave_travels (one flag per vessel, or empty for all): where the measured wave speeds
// (pwv_pressure, pwv_velocity) are a wave's; null elsewhere.
VesselTable cycle_table(const Network& net, const CycleSummary& cycle, std::vector<std::uint8_t> model,
                        std::vector<std::string> model_labels, std::vector<std::int64_t> degree,
                        const std::vector<std::uint8_t>& wave_travels = {});

// The per-vessel results, one row per vessel in the network's order: cycle_table's, and the
// linear wave theory's Womersley number and wave speeds. A measured wave speed is given only
// where a wave travels: in 1D vessels. A 0D vessel is one the pulse crosses with no lag to
// speak of (--model auto's criteria); its flow is one along it and its ends' pressures differ
// by its resistive drop, so a phase "lag" between them is no wave's (it read as 100 to
// 10,000 m/s).
// threads: the vessels' wave theory in parallel (the same numbers for any count). As
// cycle_table's, the table views the network and the cycle.
VesselTable vessel_results(const Network& net, const PulseSolver& solver, const CycleSummary& cycle,
                           double analysis_frequency, int threads = 1);

// A member of summary.json with an entry per boundary: two million on a full tree, too many
// to hold as a JSON tree (a few hundred bytes each), so written entry by entry, in the place
// and the bytes nlohmann::json gives the member among the run's facts. entry(i) is the i-th.
struct SummaryArray {
  std::string name;  // empty: none
  std::size_t size = 0;
  std::function<nlohmann::json(std::size_t)> entry;
};

// The run's facts as summary.json gives them: run, with the cycle's mass balance, volume
// change, conservation error and the units.
nlohmann::json summary_facts(const nlohmann::json& run, const CycleSummary& cycle);

// summary.json: the run's facts (`run`, and `array` among them), the mass balance and the
// vessels' results, one vessel a line. threads: the rows formatted in parallel
// (formats/parallel_rows.hpp: the same bytes for any count).
void write_summary(const std::filesystem::path& file, const nlohmann::json& run, const VesselTable& vessels,
                   const CycleSummary& cycle, const SummaryArray& array = {}, int threads = 1);

// The results summarised per class, model, generation and diameter bin (a factor sqrt(2)
// wide): each group's vessel count and the median, 5th and 95th percentile of its mean
// pressure, pulsatility index, mean flow and wall shear stress (summary.json "statistics").
// threads: the groups described in parallel (the same numbers for any count).
nlohmann::json group_statistics(const Network& net, const VesselTable& vessels, int threads = 1);

// vessels.csv: the same rows as a table, one line per vessel, a header of the fields (SI
// units; an empty field where summary.json has null), for pandas, numpy or a spreadsheet.
void write_vessel_table(const std::filesystem::path& file, const VesselTable& vessels, int threads = 1);

// The network as VTK PolyData with every numeric per-vessel result as cell data (null -> NaN).
// keep: the vessels written (one entry per vessel; empty: all).
void write_results_vtk(const std::filesystem::path& file, const Network& net, const VesselTable& vessels,
                       std::span<const std::uint8_t> keep = {});

// Appends the solution now, at every vessel's centre (p, Q, A, u), as a frame at the solver's time.
void add_solution_frame(VtkTimeSeries& series, const PulseSolver& solver);
// The same from every vessel's centre values given (a run over ranks gathers them), at time t.
void add_solution_frame(VtkTimeSeries& series, double t, std::vector<double> area, std::vector<double> flow,
                        std::vector<double> pressure);

}  // namespace hemotree
