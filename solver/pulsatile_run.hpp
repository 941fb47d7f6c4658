// The time loop of a pulsatile run: cardiac cycles of the solver, their statistics, probes,
// frames and compliance balances, until the planned cycles are done, the solution is
// periodic, it breaks down or the user interrupts it. At every cycle end the loop writes a
// checkpoint of itself (solver and progress) beside the results, made the folder's
// checkpoint.bin every --checkpoint-every cycles or on an interrupt: a run resumed from it
// continues bit for bit as if never stopped.
#pragma once

#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "formats/checkpoint_file.hpp"
#include "formats/vtk_series.hpp"
#include "solver/cycle_statistics.hpp"
#include "solver/flow_transport.hpp"
#include "solver/probes.hpp"
#include "solver/probes_over_ranks.hpp"
#include "solver/run_observer.hpp"
#include "solver/settling_cycle.hpp"
#include "pulse/pulse_solver.hpp"

namespace hemotree {

struct RunPlan {
  int cycles = 1;               // without until_periodic
  bool until_periodic = false;  // stop when the cycle-to-cycle change < periodic_tolerance
  double periodic_tolerance = 0;
  int max_cycles = 50;          // with until_periodic
  bool balance_compliances = true;
  int frames = 0;               // of the last cycle, in folder/frames
  std::vector<std::uint8_t> vtk_keep;  // the vessels the frames show (empty: all)
  std::size_t steps_per_cycle = 1;
  std::size_t sample_every = 1;  // steps between probe samples
  int checkpoint_every = 0;     // cycles; 0: only on an interrupt
  // The run's identity (solver/run_identity.hpp): a checkpoint of another is refused.
  std::uint64_t network_identity = 0;
  std::string state_shaping;    // readable, for a clear refusal of another run's checkpoint
  // The run measures its own step over its first seconds and stops (too_long) when a cycle
  // would take longer than this [s]; 0: never (--force).
  double longest_cycle = 0;
  std::size_t transport_every = 1;  // solver steps between red-cell transport steps
  // Steps of a settling cycle before the first (solver/settling_cycle.hpp); 0: none.
  std::size_t settling_steps = 0;
};

// How the time loop ended; what a run reports of it, with the checks on its numbers, is a
// RunOutcome (solver/run_outcome.hpp), which alone has words and exit statuses.
enum class RunStatus { complete, not_periodic, interrupted, broken_down, too_long };

class PulsatileRun {
 public:
  // transport: red cells carried along (advanced every plan.transport_every steps and at
  // every cycle end), or null.
  PulsatileRun(const Network& net, PulseSolver& solver, std::vector<Probe> probes, RunPlan plan,
               std::filesystem::path folder, FlowTransport* transport = nullptr);

  // Continues from a checkpoint instead of starting (InputError for one of another run).
  // checkpoint: the file's reader (its source() names it), kept where this run writes until
  // the folder is open (its first snapshot is that file), let go elsewhere. One at the run's
  // end (no cycle left to run) is taken only from a killed run's staging folder (the run's folder), whose frames of that last cycle
  // are then this run's; a published run that already has its cycles is refused as it is.
  void resume(std::unique_ptr<CheckpointReader> checkpoint);
  // Progress goes to the observer, as its progress_style() asks; its interrupt requests are
  // polled every 256 steps and answered at the last cycle end.
  RunStatus run(RunObserver& observer);
  // Whether run() has a cycle to compute (false after a resume at the run's end).
  bool cycles_left() const;
  // The frames a killed run left in the folder are this run's last cycle's, to be kept by
  // OutputFolder::open(true): resumed at the run's end, with frames asked for.
  bool keeps_frames() const { return resumed_ && !cycles_left() && plan_.frames > 0; }
  // OutputFolder::open's keep_checkpoint_as: where the checkpoint resumed from lies in the run's
  // own folder (a killed run's, which the folder's opening removes), the name of the run's
  // first snapshot, which it is; else empty (run() copies it there from the file it holds).
  std::string resumed_snapshot_name() const;

  int cycles_done() const { return done_; }
  int compliance_balances() const { return balances_; }
  const CycleSummary& last_cycle() const { return last_; }
  CycleSummary take_last_cycle() { return std::move(last_); }  // at the run's end, the report made
  // The red cells over the last cycle (empty without a transport or a cycle), and the
  // largest change of a vessel's discharge hematocrit from the cycle before (NaN before two).
  const RedCellCycle& last_red_cells() const { return red_cells_last_; }
  double red_cell_change() const { return red_cell_change_; }
  bool has_change() const { return has_previous_; }
  // The settling cycle is taken by `settling` (another discretisation of the run's network
  // and models: its 1D vessels at a lower degree), and the run starts from the state it
  // leaves (PulseSolver::start_from); without one, by the run's own solver. Before run().
  void settle_with(std::unique_ptr<PulseSolver> settling) { settling_solver_ = std::move(settling); }
  // The settling cycle taken before the first (steps 0: none), and whether an interrupt
  // stopped the run within it (nothing to keep then).
  const Settling& settling() const { return settling_; }
  bool stopped_settling() const { return settling_.signal != 0; }
  const PeriodicityChange& change() const { return change_; }
  int signal() const { return signal_; }                    // after an interrupt (RunObserver::poll_interrupt's)
  const std::string& breakdown() const { return breakdown_; }  // after a breakdown; settings as placeholders
  // Wall time per step measured over the first steps this process ran [s]; 0 before.
  double measured_step() const { return measured_step_; }
  const ProbeRecorder& probes() const { return probes_; }
  // Makes the checkpoint of the last cycle end folder/checkpoint.bin (where it is not already).
  void write_checkpoint();
  // Removes the last cycle end's snapshot where it was not made the checkpoint: before the
  // folder is published.
  void discard_snapshot();
  // The transport is freed (after the checkpoint): nothing here reads it again.
  void end_transport() { transport_ = nullptr; }

 private:
  // The checkpoint of this cycle end, written to folder/snapshot.pending: an interrupt or
  // --checkpoint-every makes it checkpoint.bin by a rename. On disk, not in memory: it is a
  // gigabyte on a full tree, which the run would otherwise hold throughout (and three times
  // over while building the next).
  // In two parts around the cycle end's balance: the cycle's results (begin_snapshot), then
  // the state it leaves (finish_snapshot), in one file, the same bytes as written at once.
  void snapshot() {
    begin_snapshot();
    finish_snapshot();
  }
  void begin_snapshot();
  void finish_snapshot();
  // The snapshot made, its identity written and its "last cycle" section begun.
  CheckpointWriter& open_snapshot();
  // Over ranks, begin_snapshot's bytes on the lead without any rank holding the whole cycle's
  // results: each rank's own (close()'s) gathered a block of the vessels at a time
  // (gather_cycle_rows), written as they come, the periodicity change and the balance's mean
  // pressures (`mean_pressure`, the lead's, where the plan balances) read from them as they
  // pass; the lead's records then in the snapshot alone (set aside). On a full tree the lead
  // held 64 B a vessel through each cycle and at each cycle end for them. Returns the lead's
  // change (nothing elsewhere). Collective.
  PeriodicityChange begin_snapshot_over_ranks(std::vector<double>& mean_pressure);
  std::optional<CheckpointWriter> snapshot_;  // between the two
  // While a cycle runs, the last cycle's per-vessel results are in its snapshot alone (80 B a
  // vessel on the run's largest moments, the cycle end's balance and the cycles after the
  // first): set aside once written, read back where a run stops within a cycle (an interrupt,
  // a breakdown, a step too slow) and reports the last cycle end; their mean pressures are
  // read back at the next cycle end, which compares them (8 B a vessel not held in between).
  void set_aside_last_vessels();
  void take_back_last_vessels();
  std::vector<double> last_mean_pressures() const;
  template <class PerVessel>
  void read_last_vessels(CheckpointStream& in, PerVessel&& per_vessel) const;
  bool last_vessels_aside_ = false;
  std::size_t own_last_vessels_ = 0;  // over ranks, a rank but the lead: how many it set aside
  std::filesystem::path latest_snapshot() const { return snapshot_pending_ ? pending() : folder_ / "checkpoint.bin"; }
  RunStatus run_cycles(RunObserver& observer);
  std::filesystem::path pending() const { return folder_ / "snapshot.pending"; }
  int planned() const { return plan_.until_periodic ? plan_.max_cycles : plan_.cycles; }
  bool periodic() const;
  void check_run_end(const std::filesystem::path& source) const;
  bool has_last_cycle_frames() const;
  void progress(RunObserver& observer, std::size_t step_in_cycle, double started);
  // A frame of every vessel's centre now (over ranks gathered on rank 0, which alone has a series).
  void add_frame(std::optional<VtkTimeSeries>& series) const;
  void sample_probes() {
    if (over_ranks_) probes_over_ranks_->sample(solver_);
    else probes_.sample(solver_);
  }

  const Network& net_;
  PulseSolver& solver_;
  RunPlan plan_;
  std::filesystem::path folder_;
  CycleStatistics stats_;
  ProbeRecorder probes_;
  CycleSummary last_;
  // The cycle before: its vessels' mean pressures, all the periodicity test compares (the
  // whole summary was 80 B a vessel more at every cycle's end).
  // Held at a cycle end until the snapshot has them; has_previous_ says there was one.
  std::vector<double> previous_mean_pressure_;
  bool has_previous_ = false;
  PeriodicityChange change_;
  Settling settling_;
  std::unique_ptr<PulseSolver> settling_solver_;  // until its cycle is taken
  int done_ = 0, balances_ = 0, signal_ = 0;
  bool resumed_ = false;
  double measured_step_ = 0;
  std::string breakdown_;
  bool snapshot_pending_ = false;  // pending() holds the last cycle end's checkpoint
  std::unique_ptr<CheckpointReader> resumed_from_;  // the checkpoint resumed from, until the folder is open (run())
  FlowTransport* transport_ = nullptr;
  RedCellCycle red_cells_last_;
  double red_cell_change_ = std::numeric_limits<double>::quiet_NaN();
  // A run over ranks (PulseSolver's PulseRanks): the decisions agreed over the ranks
  // (solver/decisions_over_ranks.hpp); the snapshot written by rank 0 (the top's) with every
  // rank's share, the one-process bytes (the last cycle's results kept in memory there); the
  // probes sampled by their vessels' ranks and gathered into probes_ at the run's end.
  bool over_ranks_ = false;
  bool writes_ = true;  // this process writes the folder's files (over ranks rank 0 alone)
  std::optional<ProbesOverRanks> probes_over_ranks_;
  // The snapshot's "run" section: the cycles done, the balances, the last change, the probes' rows.
  void put_run_progress(CheckpointWriter& out, const std::string& probe_rows) const;
};

}  // namespace hemotree
