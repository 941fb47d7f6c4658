// Where a run's results go (docs/solver.md, "Results as HDF5"): as text, summary.json (the
// run's facts, the boundaries' and the vessels' results), vessels.csv and probes.csv; or as
// HDF5, summary.json with the run's facts only and results.h5 with the facts again and the
// vessels', the boundaries' and the probes' numbers as columns, for h5py, pandas and
// parallel readers. The same numbers either way.
#pragma once

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "solver/cycle_statistics.hpp"
#include "solver/probes.hpp"
#include "solver/run_report.hpp"
#include "solver/vessel_table.hpp"

namespace hemotree {

// Named "text" and "h5" (solver/run_configuration.hpp).
enum class ResultsFormat { text, hdf5 };

struct RunResults {
  const nlohmann::json& run;        // the run's facts (summary_facts adds the cycle's)
  const VesselTable& vessels;
  const CycleSummary& cycle;
  SummaryArray boundaries;          // summary.json's per-boundary list (may be none)
  const ProbeRecorder* probes = nullptr;  // none: no probes
  int threads = 1;
};

// The results into the folder dir: summary.json and vessels.csv (and probes.csv, where there
// are probes) as text; summary.json and results.h5 as HDF5.
void write_results(const std::filesystem::path& dir, const RunResults& results, ResultsFormat format);

// results.h5 alone (the HDF5 form's file).
void write_results_hdf5(const std::filesystem::path& file, const RunResults& results);

}  // namespace hemotree
