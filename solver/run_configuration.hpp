// A pulsatile or steady run as one value: what a tool's options (or a test, a benchmark, a
// binding) ask for, checked once, and the decisions taken from it before the time loop (the
// time step a whole number of times per cycle). solver/pulsatile_call.hpp runs it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/setting_error.hpp"
#include "pulse/pulse_solver.hpp"
#include "solver/probes.hpp"
#include "solver/results_files.hpp"
#include "solver/tracer_spec.hpp"

namespace hemotree {

// Red cells: the blood's hematocrit in every vessel, or split at diverging bifurcations and
// carried by the flow (docs/transport.md).
enum class RedCells { fixed, transport };
const char* to_string(RedCells cells);          // "fixed", "transport"
const char* to_string(ModelChoice model);       // "auto", "1d", "0d"
const char* to_string(TimeScheme scheme);       // "etd2", "ab2", "rk4"
const char* to_string(StartChoice start);       // "steady", "rest", "periodic"
const char* to_string(ResultsFormat format);    // "text", "h5"

// The choices from their names, as a caller writes them (a command line, a script): a
// SettingError naming the setting (scheme, model, start, rheology, degree, red_cells) for any
// other text.
TimeScheme time_scheme_named(const std::string& name);
ModelChoice model_named(const std::string& name);
StartChoice start_named(const std::string& name);
Rheology rheology_named(const std::string& name);  // "pries" or "newtonian"
int degree_named(const std::string& name);         // "auto" (SolverOptions::automatic) or 0 to 30
int settling_degree_named(const std::string& name);  // "auto" (SolverOptions::automatic) or 0 to 30
int coupling_passes_named(const std::string& name);  // "auto" (SolverOptions::automatic) or 1 to 10
double lumped_step_named(const std::string& name);   // "auto" (0) or a fraction in (0, 0.1]
RedCells red_cells_named(const std::string& name);
ResultsFormat results_format_named(const std::string& name);

struct RunConfiguration {
  std::string network_name;  // as the caller named it (summary.json's "network")
  // Over MPI ranks, each rank but the lead holds only its slice of the network, which it
  // reads from network_name (an HDF5 file) itself (formats/network_slice.hpp): the network
  // handed to the run is then whole on rank 0 and its topology on the others.
  bool network_in_slices = false;
  std::string out_dir;       // the results folder, written as OUT.partial until the run ends
  SolverOptions solver;      // model, degrees, elements, scheme, step, wall, start, threads
  // Cycles: this many, or until every vessel's mean pressure changes by less than
  // periodic_tolerance (relative) from one cycle to the next, at most max_cycles.
  int cycles = 1;
  bool until_periodic = false;
  double periodic_tolerance = 0;
  int max_cycles = 50;
  // With until_periodic and 0D vessels: a settling cycle first, its 0D step this many times
  // the run's (solver/settling_cycle.hpp); 0 or 1: none (the default since the periodic start
  // took its mean's second-order shift, docs/solver.md §6a). In [0, 20].
  int settling_step = 0;
  // With until_periodic and 1D vessels: a settling cycle first with the 1D vessels at this
  // degree at most (a coarser discretisation of the same models, many times cheaper), the
  // compliance balance after it, and the run's first cycle from its state
  // (solver/settling_cycle.hpp); 0: none; SolverOptions::automatic: degree 2 where most
  // vessels are 1D and it costs at most a third of a cycle (pulsatile_call.cpp). In [0, 30].
  int settling_degree = SolverOptions::automatic;
  bool balance_compliances = true;
  int checkpoint_every = 0;       // cycles; 0: a checkpoint only when interrupted
  bool resume = false;            // continue from the latest checkpoint of out_dir
  double sample_interval = 1e-3;  // between probe samples [s], in (0, the period]
  std::vector<Probe> probes;
  RedCells red_cells = RedCells::fixed;
  std::vector<TracerSpec> tracers;
  double transport_step = 5e-3;   // the transport's step as a fraction of the period, in (0, 0.5]
  int frames = 0;                 // of the last cycle, as a ParaView time series
  bool vtk = false;               // results.vtp
  ResultsFormat results_format = ResultsFormat::text;  // summary.json, vessels.csv, probes.csv, or results.h5
  std::vector<std::uint8_t> vtk_keep;  // the vessels the VTK output shows (empty: all)
  // Run even beyond the stability limit, a day per cycle, or over a killed run's checkpoint.
  bool force = false;
  // The caller's words for the settings that the run's kept texts name (summary.json's
  // time-step reason and error, the notes and warnings to the observer): hemosolve's flags;
  // empty, the settings' own names. What the run throws is a SettingError the catcher words.
  SettingWords words;

  bool carries_transport() const { return red_cells == RedCells::transport || !tracers.empty(); }
  int planned_cycles() const { return until_periodic ? max_cycles : cycles; }
};

// The configuration's own ranges, before any work: a SettingError naming the setting by its
// own name ("cycles", "max_cycles", "periodic_tolerance", "low_degree", "transport_step", ...),
// which the caller words (hemosolve: its flags, cli/setting_words.cpp).
void check_configuration(const RunConfiguration& config);

// The solver's options as the run takes them: with red cells or tracers, every 0D vessel one
// pi section (their cells are the network's nodes; a vessel in sections holds volume at inner
// nodes of its own), so a vessel that needs more is 1D, as it is with --lumped-sections 1.
SolverOptions solver_options(const RunConfiguration& config);

// A cycle of N steps of dt = T / N: the step no longer than the solver's, N = ceil(T / step)
// (less 1e-9 of a step, so that a step that divides the period is kept), so that every
// cycle ends exactly on a step. InputError when N is beyond any machine's reach.
struct CycleStep {
  std::size_t steps_per_cycle = 1;
  double dt = 0;  // [s]
};
CycleStep decide_cycle_step(double period, double step, const std::string& reason);

// The run's time step, decided here alone: the solver's (its stability limit, or the one
// asked for), refused above the limit unless forced, rounded to a whole number per cycle and
// set on the solver.
struct TimeStepDecision {
  CycleStep cycle;
  std::string reason;        // what limits the step (the solver's words)
  std::string beyond_limit;  // a forced step above the limit, said; empty otherwise
};
TimeStepDecision decide_time_step(PulseSolver& solver, const RunConfiguration& config, double period);

}  // namespace hemotree
