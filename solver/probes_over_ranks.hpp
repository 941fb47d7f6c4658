// Probes over ranks (`hemosolve --probe` in a run over ranks): each rank samples the probes
// on the vessels it steps, as numbers; at the run's end rank 0 gathers them and writes the
// very rows ProbeRecorder writes alone (docs/scaling.md, "The pulsatile run over ranks").
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "pulse/pulse_solver.hpp"
#include "solver/probes.hpp"

namespace hemotree {

class ProbesOverRanks {
 public:
  // probes: the run's, in its order; this rank keeps those on the vessels it steps.
  ProbesOverRanks(const std::vector<Probe>& probes, const PulseSolver& solver);
  // Further columns at every probe (ProbeRecorder::add_columns'), sampled with the rest.
  void add_columns(std::size_t count, std::function<double(std::size_t, const Probe&)> value) {
    columns_ = count;
    column_ = std::move(value);
  }
  // One sample at the solver's time: every rank at the same steps.
  void sample(const PulseSolver& solver);
  // Collective over MPI_COMM_WORLD: rank 0's recorder (of the run's probes, in their order)
  // gets one row per sample; elsewhere it is left as it is.
  void gather_into(ProbeRecorder& recorder) const;
  const std::vector<Probe>& probes() const { return probes_; }

 private:
  std::vector<Probe> probes_;         // the run's
  std::vector<std::int32_t> mine_;    // their places, of those on this rank's vessels
  std::vector<double> times_;         // per sample
  std::vector<double> values_;        // per sample, per probe of mine_: p, Q, A and the columns
  std::size_t columns_ = 0;
  std::function<double(std::size_t, const Probe&)> column_;
};

}  // namespace hemotree
