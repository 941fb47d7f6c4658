// hemosolve --steady: the steady state alone (what Secomb's NetFlow computes for a measured
// network), reported in the same files and fields as a pulsatile run: each cycle value is the
// steady one (systolic = diastolic = mean pressure, pulsatility 0, peak = least = mean flow),
// and what only waves have (wave speeds, Womersley numbers) is null.
#pragma once

#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "formats/network.hpp"
#include "solver/cycle_statistics.hpp"
#include "solver/run_observer.hpp"
#include "solver/results_files.hpp"
#include "solver/run_report.hpp"
#include "steady/steady_flow.hpp"
#include "solver/vessel_table.hpp"

namespace hemotree {

// Per vessel its flow (signed: positive from `from` to `to`), the pressure at its middle
// (the mean of its ends': Poiseuille's profile is linear), the wall shear stress and Reynolds
// number of its mean velocity in its reference lumen; per run the flows in and out through
// the boundaries (their balance is the solve's round-off).
// hematocrit: each vessel's discharge hematocrit for its viscosity, or null: the blood's.
CycleSummary steady_cycle(const Network& net, const Blood& blood, const SteadyFlow& steady,
                          const std::vector<double>* hematocrit = nullptr);
// The run's part of it alone: the flows in and out through the boundaries and their balance
// (for a caller that fills the vessels' own: --linear).
void add_boundary_flows(const Network& net, const SteadyFlow& steady, CycleSummary& cycle);

// Every boundary node's condition and what the solve gives there: {"node", "type", "flow"
// (into the network, m^3/s), "pressure" (Pa)}, by node.
SummaryArray boundary_results(const Network& net, const SteadyFlow& steady);

// cycle_table's columns with the model "steady" and no degree, and null wave columns.
VesselTable steady_results(const Network& net, const CycleSummary& cycle);

struct SteadyRunRequest {
  std::string input;               // as given, for summary.json
  std::filesystem::path out_dir;
  int rheology_override = -1;      // -1: the file's; else static_cast<int>(Rheology)
  bool vtk = false;
  std::span<const std::uint8_t> vtk_keep;
  // Red cells: fixed (the blood's hematocrit everywhere) or phase separation at diverging
  // bifurcations, the flows and hematocrits solved together (steady/steady_hematocrit.hpp).
  bool phase_separation = false;
  int threads = 1;  // the first resistances and the report in parallel (the same bytes for any count)
  ResultsFormat results_format = ResultsFormat::text;
  // Over MPI ranks: the network is whole on rank 0 and its topology on the others, which read
  // their slices of `input` (distributed/steady_on_slices.hpp).
  bool network_in_slices = false;
};

// Solves and writes OUT/summary.json, OUT/vessels.csv or OUT/results.h5 (and OUT/results.vtp with vtk) through
// OutputFolder (never a half-written folder). InputError for a network it cannot solve. With
// phase separation each vessel's discharge and tube hematocrit are reported too; an iteration
// that does not converge writes its last state marked "not converged" and is InputError.
// The observer hears the one note of a steady run (its time and where its results are).
void run_steady(const Network& net, const SteadyRunRequest& request, RunObserver& observer);

}  // namespace hemotree
