#include "solver/pulsatile_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <functional>
#include <utility>

#include "core/errors.hpp"
#include "core/free_memory.hpp"
#include "core/setting_error.hpp"
#include "formats/vtk_series.hpp"
#include "mpi/session.hpp"
#include "solver/cycle_over_ranks.hpp"
#include "solver/decisions_over_ranks.hpp"
#include "solver/run_report.hpp"
#include "pulse/solution_breakdown.hpp"

namespace hemotree {

namespace {
double seconds_since_epoch_start() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// A cycle's summary as numbers, for the checkpoint: given vessel by vessel, not assembled,
// a row each (cycle_row). The section's head: its length, then the cycle's sums; a row per
// vessel follows, then the boundaries' mean flows.
void put_summary_head(CheckpointWriter& out, const CycleSummary& c, std::size_t vessels) {
  out.begin_vector(4 + cycle_row_width * vessels);
  out.put_part(std::vector<double>{c.inlet_mean_flow, c.outlets_mean_flow, c.volume_change, c.conservation_error});
}
void put_summary(CheckpointWriter& out, const CycleSummary& c) {
  put_summary_head(out, c, c.vessels.size());
  auto wave = c.waves.begin();
  for (std::size_t k = 0; k < c.vessels.size(); ++k) {
    const VesselCycle& v = c.vessels[k];
    WaveSpeeds speeds;
    if (wave != c.waves.end() && wave->first == k) speeds = (wave++)->second;
    out.put_part(cycle_row(v, speeds));
  }
  out.put(c.boundary_mean_flow);
}

// Read vessel by vessel (the section is 80 B a vessel: not held whole besides the results).
// entries: where given, the vessel of each entry kept (a rank's own, CycleStatistics'
// entry_vessels()), the results then by entry (the waves by vessel, as close() leaves them);
// else every vessel's, by vessel.
CycleSummary get_summary(CheckpointReader& in, std::size_t vessels, std::span<const std::int32_t> entries = {}) {
  const std::uint64_t count = in.begin_vector();
  if (count != 4 && count != 4 + cycle_row_width * vessels) in.fail("cycle results of another network");
  CycleSummary c;
  double f[cycle_row_width];
  in.get_part(std::span<double>(f, 4));
  c.inlet_mean_flow = f[0];
  c.outlets_mean_flow = f[1];
  c.volume_change = f[2];
  c.conservation_error = f[3];
  if (count > 4) {
    // Each kept entry at its place: (vessel, entry) in the vessels' order.
    std::vector<std::pair<std::int32_t, std::int32_t>> kept;
    for (std::size_t e = 0; e < entries.size(); ++e) kept.emplace_back(entries[e], static_cast<std::int32_t>(e));
    std::ranges::sort(kept);
    const bool all = entries.empty();
    c.vessels.resize(all ? vessels : entries.size());
    auto next = kept.begin();
    for (std::size_t v = 0; v < vessels; ++v) {
      in.get_part(f);
      bool kept_here = all;
      if (all) c.vessels[v] = row_cycle(f);
      for (; next != kept.end() && static_cast<std::size_t>(next->first) == v; ++next, kept_here = true)
        c.vessels[static_cast<std::size_t>(next->second)] = row_cycle(f);
      const WaveSpeeds speeds = row_wave_speeds(f);
      if (kept_here && (!std::isnan(speeds.pressure) || !std::isnan(speeds.velocity))) c.waves.emplace_back(v, speeds);
    }
  }
  c.boundary_mean_flow = in.get_vector();
  return c;
}

// What a breakdown's usual advice (a shorter step) misses where the vessel is 1D with an end
// at a node of 0D vessels: there each coupled end takes its node's own response alone, and a
// shorter 0D step can make the coupling's fixed point diverge (docs/solver.md §10, "A known
// limit": ADAN56 breaks down at a quarter of its default step and runs at the default).
std::string coupling_advice(const Network& net, const NetworkBoundaries& boundaries, std::int64_t vessel_id) {
  const std::int64_t vessel = net.index_of(vessel_id);
  for (const NetworkBoundaries::CoupledEnd& c : boundaries.coupled)
    if (c.end.vessel == vessel)
      return "; its end meets 0D vessels, whose coupling to it a shorter step can itself break (docs/solver.md, "
             "section 10): where " + placeholder("dt") + " was shortened, a longer one (the default) may run";
  return "";
}
}  // namespace

PulsatileRun::PulsatileRun(const Network& net, PulseSolver& solver, std::vector<Probe> probes, RunPlan plan,
                           std::filesystem::path folder, FlowTransport* transport)
    : net_(net), solver_(solver), plan_(std::move(plan)), folder_(std::move(folder)),
      stats_(net, solver, analysis_frequency(driving_waveform(net))), probes_(probes), transport_(transport),
      over_ranks_(solver.over_ranks()), writes_(!over_ranks_ || world_rank() == 0) {
  plan_.transport_every = std::max<std::size_t>(plan_.transport_every, 1);
  if (over_ranks_) {
    if (writes_ && !solver.holds_one_d()) throw std::logic_error("PulsatileRun over ranks: rank 0 is not the top's");
    probes_over_ranks_.emplace(probes, solver);
  }
  if (!transport_) return;
  // probes.csv: the discharge hematocrit and each tracer's concentration at every probe.
  std::vector<std::string> headers;
  if (transport_->reports_red_cells()) headers.push_back("H_D [1]");
  for (const TracerSpec& t : transport_->tracer_specs())
    headers.push_back("c_" + t.name + " [per " + (t.carrier == TracerCarrier::cells ? "red-cell" : to_string(t.carrier)) +
                      " volume]");
  const bool red = transport_->reports_red_cells();
  auto column = [this, red](std::size_t j, const Probe& p) {
    if (red && j == 0) return transport_->hematocrit_at(p.vessel, p.x);
    return transport_->tracer_at(j - (red ? 1 : 0), p.vessel, p.x);
  };
  if (probes_over_ranks_) probes_over_ranks_->add_columns(headers.size(), column);
  probes_.add_columns(std::move(headers), column);
}

void PulsatileRun::begin_snapshot() {
  snapshot_pending_ = false;
  if (!writes_) return;  // over ranks rank 0's, which gathers the cycle's results and holds the top
  CheckpointWriter& out = open_snapshot();
  put_summary(out, last_);
  out.section("previous cycle");
  out.put(previous_mean_pressure_);
}

CheckpointWriter& PulsatileRun::open_snapshot() {
  snapshot_.emplace(pending());
  CheckpointWriter& out = *snapshot_;
  out.section("identity");
  out.put(plan_.network_identity);
  out.put(plan_.state_shaping);
  out.section("last cycle");
  return out;
}

PeriodicityChange PulsatileRun::begin_snapshot_over_ranks(std::vector<double>& mean_pressure) {
  snapshot_pending_ = false;
  const std::size_t n = net_.vessel_count();
  CheckpointWriter* out = nullptr;
  if (writes_) {
    out = &open_snapshot();
    put_summary_head(*out, last_, n);
    if (plan_.balance_compliances) mean_pressure.assign(n, 0.0);
  }
  // Each block's rows as begin_snapshot writes them, each vessel's change as cycle_change
  // takes it, in the vessels' order.
  PeriodicityChange worst;
  const bool compare = !previous_mean_pressure_.empty();
  std::vector<std::pair<std::size_t, WaveSpeeds>> waves;
  gather_cycle_rows(net_, solver_, last_, stats_.entry_vessels(solver_), [&](std::size_t first, std::span<const double> rows) {
    out->put_part(rows);
    for (std::size_t k = 0; k * cycle_row_width < rows.size(); ++k) {
      const double* f = rows.data() + k * cycle_row_width;
      const std::size_t v = first + k;
      const double p = row_cycle(f).mean_pressure;
      if (compare) worst.compare(v, previous_mean_pressure_[v], p);
      if (!mean_pressure.empty()) mean_pressure[v] = p;
      if (!solver_.is_lumped(v)) waves.emplace_back(v, row_wave_speeds(f));
    }
  });
  if (!writes_) return worst;
  out->put(last_.boundary_mean_flow);
  out->section("previous cycle");
  out->put(previous_mean_pressure_);
  // In the snapshot alone from here, as a plain run's are once written (set_aside_last_vessels).
  last_.waves = std::move(waves);
  std::vector<VesselCycle>().swap(last_.vessels);
  std::vector<double>().swap(last_.boundary_mean_flow);
  last_vessels_aside_ = true;
  return worst;
}

void PulsatileRun::finish_snapshot() {
  if (over_ranks_) {
    // Every rank's share of the probes and of the solver's state, to rank 0's file: the
    // bytes the one-process run writes (the probes' rows so far, after any resumed).
    ProbeRecorder probes(probes_over_ranks_->probes());
    probes.add_columns(probes_.column_headers(), {});
    probes.restore_rows(probes_.rows());
    probes_over_ranks_->gather_into(probes);
    if (writes_) {
      put_run_progress(*snapshot_, probes.rows());
      solver_.save_over_ranks(&*snapshot_);
      if (transport_) transport_->save_over_ranks(&*snapshot_);
    } else {
      solver_.save_over_ranks(nullptr);
      if (transport_) transport_->save_over_ranks(nullptr);
      return;
    }
  } else {
    put_run_progress(*snapshot_, probes_.rows());
    solver_.save(*snapshot_);
  }
  CheckpointWriter& out = *snapshot_;
  if (transport_) {
    if (!over_ranks_) transport_->save(out);
    out.put(red_cells_last_.discharge);
    out.put(red_cells_last_.lowest);
    out.put(red_cells_last_.highest);
    out.put(std::vector<double>{red_cells_last_.red_cells, red_cells_last_.entered, red_cells_last_.left,
                                red_cells_last_.balance_error, static_cast<double>(red_cells_last_.separating_nodes),
                                red_cell_change_});
  }
  out.section("end");
  out.finish();
  snapshot_.reset();
  snapshot_pending_ = true;
}

void PulsatileRun::put_run_progress(CheckpointWriter& out, const std::string& probe_rows) const {
  out.section("run");
  out.put(static_cast<std::uint64_t>(done_));
  out.put(static_cast<std::uint64_t>(balances_));
  out.put(change_.change);
  out.put(static_cast<std::uint64_t>(change_.vessel));
  out.put(probe_rows);
}

void PulsatileRun::set_aside_last_vessels() {
  // Over ranks the lead's snapshot holds them. Every other rank has sent its own vessels' (by
  // entry: CycleStatistics) to the lead, and reads nothing of them again but whether there
  // were any (has_previous_ at the next cycle end): 64 B an own vessel less through every
  // cycle after the first.
  if (!writes_) {
    if (!last_.vessels.empty()) own_last_vessels_ = last_.vessels.size();
    std::vector<VesselCycle>().swap(last_.vessels);
    return;
  }
  if (last_.vessels.empty()) return;
  std::vector<VesselCycle>().swap(last_.vessels);  // its waves, a few hundred, stay
  std::vector<double>().swap(last_.boundary_mean_flow);
  last_vessels_aside_ = true;
}

// The "last cycle" section of the latest snapshot, each vessel's results handed to
// per_vessel(v, results) in the network's order, the section's totals skipped; the stream is
// left after the vessels (at the boundary flows).
template <class PerVessel>
void PulsatileRun::read_last_vessels(CheckpointStream& in, PerVessel&& per_vessel) const {
  in.section("identity");
  in.section("last cycle");
  const std::size_t n = net_.vessel_count();
  if (in.get_u64() != 4 + cycle_row_width * n)
    throw InputError(latest_snapshot().string() + ": cycle results of another network");
  double f[cycle_row_width];
  in.get_doubles(std::span<double>(f, 4));  // the totals, which the run kept
  for (std::size_t v = 0; v < n; ++v) {
    in.get_doubles(f);
    per_vessel(v, row_cycle(f));
  }
}

void PulsatileRun::take_back_last_vessels() {
  if (!last_vessels_aside_) return;
  CheckpointStream in(latest_snapshot());
  last_.vessels.resize(net_.vessel_count());
  read_last_vessels(in, [&](std::size_t v, const VesselCycle& c) { last_.vessels[v] = c; });
  if (in.get_u64() != solver_.boundary_list().size())
    throw InputError(latest_snapshot().string() + ": cycle results of another network");
  last_.boundary_mean_flow.resize(solver_.boundary_list().size());
  in.get_doubles(last_.boundary_mean_flow);
  in.finish();
  last_vessels_aside_ = false;
}

std::vector<double> PulsatileRun::last_mean_pressures() const {
  std::vector<double> p(net_.vessel_count());
  CheckpointStream in(latest_snapshot());
  read_last_vessels(in, [&](std::size_t v, const VesselCycle& c) { p[v] = c.mean_pressure; });
  in.finish();
  return p;
}

void PulsatileRun::resume(std::unique_ptr<CheckpointReader> checkpoint) {
  CheckpointReader& in = *checkpoint;
  const std::string source = in.source();
  in.section("identity");
  if (in.get_u64() != plan_.network_identity) in.fail("written for another network (its fingerprint differs)");
  const std::string options = in.get_string();
  if (options != plan_.state_shaping)
    in.fail("written by a run with other options (there: " + options + "; here: " + plan_.state_shaping + ")");
  // Over ranks every rank but the one that writes keeps only how many of its own vessels'
  // results there were (as a cycle's end leaves it), and no mean pressures of the cycle
  // before (the lead alone tests the change).
  in.section("last cycle");
  if (writes_) {
    last_ = get_summary(in, net_.vessel_count());  // whole, set aside at the run's start
  } else {
    last_ = get_summary(in, net_.vessel_count(), stats_.entry_vessels(solver_));
    set_aside_last_vessels();
  }
  in.section("previous cycle");
  std::uint64_t previous = 0;
  if (writes_) {
    previous_mean_pressure_ = in.get_vector();
    previous = previous_mean_pressure_.size();
  } else {
    previous = in.skip_vector();
  }
  if (previous != 0 && previous != net_.vessel_count()) in.fail("cycle results of another network");
  has_previous_ = previous != 0;
  in.section("run");
  done_ = static_cast<int>(in.get_u64());
  balances_ = static_cast<int>(in.get_u64());
  change_.change = in.get_double();
  change_.vessel = static_cast<std::size_t>(in.get_u64());
  probes_.restore_rows(in.get_string());
  solver_.restore(in);
  if (transport_) {
    transport_->restore(in);
    red_cells_last_.discharge = in.get_vector();
    red_cells_last_.lowest = in.get_vector();
    red_cells_last_.highest = in.get_vector();
    const std::vector<double> totals = in.get_vector();
    if (totals.size() != 6) in.fail("red-cell results of another version");
    red_cells_last_.red_cells = totals[0];
    red_cells_last_.entered = totals[1];
    red_cells_last_.left = totals[2];
    red_cells_last_.balance_error = totals[3];
    red_cells_last_.separating_nodes = static_cast<std::size_t>(totals[4]);
    red_cell_change_ = totals[5];
  }
  in.section("end");
  if (!in.at_end()) in.fail("unexpected bytes after the checkpoint");
  resumed_ = true;
  if (writes_) resumed_from_ = std::move(checkpoint);  // the snapshot as it is until a cycle ends (copied once the folder is open)
  if (!cycles_left()) check_run_end(source);
}

std::string PulsatileRun::resumed_snapshot_name() const {
  return resumed_from_ && std::filesystem::path(resumed_from_->source()).parent_path() == folder_ ? pending().filename().string()
                                                                                                   : std::string();
}

bool PulsatileRun::periodic() const {
  // With red cells carried, their distribution must have settled too: its largest change of
  // a vessel's cycle-mean discharge hematocrit below the same tolerance.
  return plan_.until_periodic && has_change() && change_.change < plan_.periodic_tolerance &&
         (!transport_ || red_cell_change_ < plan_.periodic_tolerance);
}

bool PulsatileRun::cycles_left() const { return done_ < planned() && !periodic(); }

// A checkpoint with no cycle left to run: the run ends where it ended, and its results are
// written from the checkpoint. Right only where the results of that end are not already
// published, and where the frames of its last cycle are at hand: a run killed between its
// last checkpoint and publishing its folder left both in its staging folder.
void PulsatileRun::check_run_end(const std::filesystem::path& source) const {
  const std::string cycles = std::to_string(done_) + (done_ == 1 ? " cycle" : " cycles");
  const std::string raise = placeholder(plan_.until_periodic ? "max_cycles" : "cycles");
  const std::string resume = placeholder("resume");
  if (source.parent_path() != folder_) {
    const std::string dir = source.parent_path().string();
    if (periodic())
      throw SettingError("resume", resume + " " + dir + ": the run is already periodic after its " + cycles +
                                       "; nothing is left to run");
    throw SettingError("resume", resume + " " + dir + ": the run already has its " + cycles + "; raise " + raise +
                                     " to continue");
  }
  if (done_ > planned())
    throw SettingError("resume", resume + ": " + source.string() + " is after cycle " + std::to_string(done_) +
                                     ", beyond " + raise + " " + std::to_string(planned()) + "; raise " + raise +
                                     " to continue");
  if (!has_last_cycle_frames())
    throw SettingError("resume", resume + ": " + source.string() + " ends the run after its " + cycles +
                                     ", but the frames of that last cycle are not in " +
                                     (folder_ / "frames").string() + " as " + placeholder("frames") + " " +
                                     std::to_string(plan_.frames) + " asks; raise " + raise +
                                     " to compute another cycle's");
}

// The folder's frames/frames.pvd lists the frames of the cycle that ended at the
// checkpoint's time, as many as the plan asks, and each is there. (A series removes its .pvd
// when a cycle begins and writes it when the cycle's frames are complete.)
bool PulsatileRun::has_last_cycle_frames() const {
  if (plan_.frames == 0) return true;
  const std::filesystem::path dir = folder_ / "frames";
  std::ifstream in(dir / "frames.pvd");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<double> times;
  std::error_code ec;
  for (std::size_t at = text.find("<DataSet"); at != std::string::npos; at = text.find("<DataSet", at + 1)) {
    const std::size_t time_at = text.find("timestep=\"", at), file_at = text.find("file=\"", at);
    if (time_at == std::string::npos || file_at == std::string::npos) return false;
    const std::size_t name_at = file_at + 6, name_end = text.find('"', name_at);
    if (name_end == std::string::npos || !std::filesystem::is_regular_file(dir / text.substr(name_at, name_end - name_at), ec))
      return false;
    times.push_back(std::strtod(text.c_str() + time_at + 10, nullptr));
  }
  const double period = solver_.period(), end = solver_.time();
  // The .pvd keeps 9 significant digits of each time; another cycle's lie a period away.
  return times.size() == static_cast<std::size_t>(plan_.frames) &&
         std::abs(times.back() - end) <= 1e-6 * period + 1e-8 * std::abs(end) && times.front() > end - period;
}

void PulsatileRun::write_checkpoint() {
  if (!snapshot_pending_) return;  // checkpoint.bin is the last cycle end's already
  promote_checkpoint_file(pending(), folder_ / "checkpoint.bin");
  snapshot_pending_ = false;
}

void PulsatileRun::discard_snapshot() {
  if (!writes_) return;
  std::error_code ec;
  std::filesystem::remove(pending(), ec);
  snapshot_pending_ = false;
}

void PulsatileRun::add_frame(std::optional<VtkTimeSeries>& series) const {
  if (!over_ranks_) {
    add_solution_frame(*series, solver_);
    return;
  }
  // Every vessel's centre from the rank that steps it, written by rank 0.
  std::vector<double> area, flow, pressure;
  solver_.sample_all(0.5, area, flow, &pressure);
  std::vector<double>* columns[] = {&area, &flow, &pressure};
  gather_vessel_values(net_, solver_, columns);
  if (series) add_solution_frame(*series, solver_.time(), std::move(area), std::move(flow), std::move(pressure));
}

void PulsatileRun::progress(RunObserver& observer, std::size_t k, double started) {
  const double elapsed = seconds_since_epoch_start() - started;
  const double rate = static_cast<double>(k + 1) / std::max(elapsed, 1e-9);
  const double left = static_cast<double>(plan_.steps_per_cycle - k - 1) / rate;
  observer.live_progress(done_ + 1, planned(), solver_.time(), rate, left);
}

RunStatus PulsatileRun::run(RunObserver& observer) {
  const RunStatus status = run_cycles(observer);
  if (over_ranks_) probes_over_ranks_->gather_into(probes_);  // rank 0's: every probe's rows
  if (over_ranks_ && transport_) transport_->take_reports();  // rank 0's: the tracers' curves and balances
  // The time loop is over: its 0D state (1.2 GB on the full tree) freed before the last
  // cycle's records are read back, not beside them (the run's end was a lead's largest moment).
  solver_.release_lumped_state();
  return_free_memory();  // (its arrays lay in the allocator's heap, whose freed pages stay resident)
  take_back_last_vessels();  // what the report describes, however the run stopped
  return status;
}

RunStatus PulsatileRun::run_cycles(RunObserver& observer) {
  const bool live = observer.progress_style() == ProgressStyle::live;
  const bool log = observer.progress_style() == ProgressStyle::log;
  const double period = solver_.period();
  // Statistics every 1e-4 of a period (or every step if that is longer): means and extrema
  // of the smooth pulse are then exact to ~1e-7, at a few per cent of the run's time. With
  // 0D vessels the steps are few (1e-3 of the period) and a sample costs as much as a step
  // (every vessel, three points): every 2e-3 of the period, which moved no pulsatility index
  // of the 1001-vessel network by more than 0.012 % (every 4e-3: 0.13 %).
  const double samples_per_cycle = solver_.lumped_vessels_in_run() > 0 ? 500 : 1e4;
  const auto stats_every = std::max<std::size_t>(
      1, static_cast<std::size_t>(static_cast<double>(plan_.steps_per_cycle) / samples_per_cycle));
  if (!resumed_) {
    if (plan_.settling_steps > 0) {
      // Not a cycle of the run's: nothing of it is reported or kept, and an interrupt
      // within it leaves nothing to resume from.
      const bool coarse = settling_solver_ != nullptr;
      observer.note("settling cycle: " + std::to_string(plan_.settling_steps) + " steps" +
                    (coarse ? " with the 1D vessels at degree " + std::to_string(settling_solver_->max_degree()) + " at most" : "") +
                    ", then the compliance balance");
      try {
        settling_ = settle(net_, coarse ? *settling_solver_ : solver_, plan_.settling_steps, observer);
      } catch (const SolutionBreakdown& e) {
        // The options are named through their placeholders (core/setting_error.hpp), which the
        // tool words. The 0D step's settling cycle is taken only when asked for; the low
        // degree's by default where most vessels are 1D, so its advice is the value that
        // turns it off.
        breakdown_ = e.message() + "; it broke down in the settling cycle, " +
                     (coarse ? "whose 1D vessels take a lower degree than the run's (with " + placeholder("settling_degree") +
                                   " 0 the run takes none)"
                             : "whose 0D step is longer than the run's (without " + placeholder("settling_step") +
                                   ", the default, the run takes none)");
        return RunStatus::broken_down;
      }
      if ((signal_ = settling_.signal) != 0) return RunStatus::interrupted;
      if (coarse) {
        settling_.degree = settling_solver_->max_degree();
        solver_.start_from(*settling_solver_);
        settling_solver_.reset();
        if (plan_.balance_compliances) solver_.balance_compliances(period);  // the first cycle's start
      }
      if (transport_) transport_->restart();  // the cells did not move with it
      observer.note("settling cycle done in " + std::to_string(std::lround(settling_.seconds)) + " s");
    } else if (plan_.balance_compliances) {
      solver_.balance_compliances(period);  // the first cycle's start
    }
    sample_probes();
    if (transport_) transport_->take_volumes();
    snapshot();
  } else if (resumed_from_) {
    // The checkpoint resumed from is the first snapshot: moved here as it is by the folder's
    // opening (resumed_snapshot_name), or copied from the file held open.
    if (!resumed_from_->reads(pending())) resumed_from_->write_copy(pending());
    snapshot_pending_ = true;
    resumed_from_.reset();
    set_aside_last_vessels();
  }
  try {
    while (cycles_left()) {
      std::optional<VtkTimeSeries> series;  // each cycle could be the last: its frames replace the previous
      if (plan_.frames > 0 && writes_) series.emplace(net_, folder_ / "frames", "frames", plan_.vtk_keep);
      std::size_t frames_written = 0;
      return_free_memory();  // what the set-up or the last cycle end freed, before the loop's arrays
      stats_.begin(solver_);
      if (transport_) transport_->begin_cycle();
      double sampled_until = solver_.time();
      const double started = seconds_since_epoch_start();
      // A share of a run over ranks takes a step's statistics in the next step, while the
      // top's rank takes its 1D substeps and the share would wait (its state is still that
      // step's end then): the same sums, off the share's part of the step. The cycle's last
      // step's at once.
      const bool sample_while_waiting = over_ranks_ && !solver_.holds_one_d();
      std::optional<std::pair<double, double>> waiting_sample;  // (t, weight)
      const std::function<void()> take_waiting_sample = [&] {
        if (!waiting_sample) return;
        stats_.sample(solver_, waiting_sample->first, waiting_sample->second);
        waiting_sample.reset();
      };
      for (std::size_t k = 0; k < plan_.steps_per_cycle; ++k) {
        solver_.step(take_waiting_sample);
        if (transport_ && ((k + 1) % plan_.transport_every == 0 || k + 1 == plan_.steps_per_cycle)) transport_->advance();
        if ((k + 1) % stats_every == 0 || k + 1 == plan_.steps_per_cycle) {
          if (sample_while_waiting && k + 1 < plan_.steps_per_cycle) waiting_sample.emplace(solver_.time(), solver_.time() - sampled_until);
          else stats_.sample(solver_, solver_.time(), solver_.time() - sampled_until);
          sampled_until = solver_.time();
        }
        if (plan_.frames > 0 && (k + 1) * static_cast<std::size_t>(plan_.frames) >= (frames_written + 1) * plan_.steps_per_cycle) {
          add_frame(series);
          ++frames_written;
        }
        if (solver_.steps() % plan_.sample_every == 0) sample_probes();
        if (k % 256 == 0) {
          signal_ = observer.poll_interrupt();
          if (over_ranks_) signal_ = interrupt_on_any_rank(signal_);
          if (signal_ != 0) {
            // Back to the last cycle end: what the summary and the checkpoint describe.
            if (live) observer.clear_live_progress();
            return RunStatus::interrupted;
          }
          if (live) progress(observer, k, started);
        }
        // The cost model's estimate, checked against this machine once the first second or
        // thousand steps have gone by (a clock reading a step until then). Over ranks at the
        // same step on every rank, the slowest rank's: every rank stops or none.
        if (measured_step_ == 0) {
          const double elapsed = seconds_since_epoch_start() - started;
          const std::size_t first_steps = std::min<std::size_t>(1024, plan_.steps_per_cycle);
          if (over_ranks_ ? k + 1 == first_steps : elapsed > 1 || k + 1 >= first_steps) {
            measured_step_ = (over_ranks_ ? largest_on_ranks(elapsed) : elapsed) / static_cast<double>(k + 1);
            if (plan_.longest_cycle > 0 && measured_step_ * static_cast<double>(plan_.steps_per_cycle) > plan_.longest_cycle) {
              if (live) observer.clear_live_progress();
              return RunStatus::too_long;
            }
          }
        }
      }
      if (over_ranks_) check_solution_on_every_rank(solver_);
      else solver_.check_solution();
      // The cycle end (statistics, compliance balance, snapshot) takes no step: on the full
      // tree 0.26 GB of the step's arrays less at what is the run's largest moment.
      solver_.release_step_arrays();
      if (last_vessels_aside_) {
        previous_mean_pressure_ = last_mean_pressures();  // before this cycle end's snapshot replaces it
        last_vessels_aside_ = false;
      } else {
        previous_mean_pressure_ = mean_pressures(last_.vessels);
      }
      last_ = CycleSummary{};  // freed before the next is built
      // The cycle's results go to the snapshot, and from memory (but their mean pressures,
      // which the balance and the next cycle end read) before the balance; the previous
      // cycle's mean pressures have served.
      std::vector<double> mean_pressure;  // the balance's, the lead's
      last_ = stats_.close(solver_);
      if (series) series->finish();
      // (A rank other than the lead holds no mean pressures to compare, only whether it had a cycle.)
      has_previous_ = writes_ ? !previous_mean_pressure_.empty() : own_last_vessels_ > 0;
      if (over_ranks_) {
        // Every rank its own vessels' results (by entry: CycleStatistics), which go to the
        // lead's snapshot a block at a time; the lead alone tests the change.
        const PeriodicityChange change = begin_snapshot_over_ranks(mean_pressure);
        if (has_change()) change_ = lead_change(change);
      } else {
        if (has_change()) change_ = cycle_change(previous_mean_pressure_, last_.vessels);
        begin_snapshot();
        if (plan_.balance_compliances) mean_pressure = mean_pressures(last_.vessels);
      }
      std::vector<double>().swap(previous_mean_pressure_);
      if (plan_.balance_compliances) {
        set_aside_last_vessels();
        if (solver_.balance_compliances(period, std::move(mean_pressure)) > 0) ++balances_;
      } else {
        set_aside_last_vessels();
      }
      if (transport_) {
        RedCellCycle cycle = transport_->close_cycle();
        if (!red_cells_last_.discharge.empty()) {
          red_cell_change_ = 0;
          for (std::size_t v = 0; v < cycle.discharge.size(); ++v)
            red_cell_change_ = std::max(red_cell_change_, std::abs(cycle.discharge[v] - red_cells_last_.discharge[v]));
          if (over_ranks_) {  // rank 0 alone has the whole cycle
            std::vector<double> change{red_cell_change_};
            take_lead_values(change);
            red_cell_change_ = change[0];
          }
        }
        red_cells_last_ = std::move(cycle);
        transport_->take_volumes();  // the balance's shifts, and the 0D nodes' round-off
      }
      ++done_;
      finish_snapshot();
      if (plan_.checkpoint_every > 0 && done_ % plan_.checkpoint_every == 0) write_checkpoint();
      if (live) observer.clear_live_progress();
      if (log) {
        const double wall = seconds_since_epoch_start() - started;
        std::string line = "cycle " + std::to_string(done_) + "/" + std::to_string(planned()) + " done in " +
                           std::to_string(static_cast<long long>(std::lround(wall))) + " s";
        if (has_change()) {
          char text[64];
          std::snprintf(text, sizeof text, "; change %.3g (vessel %lld)", change_.change,
                        static_cast<long long>(net_.id[change_.vessel]));
          line += text;
        }
        observer.note(line);
      }
    }
  } catch (const SolutionBreakdown& e) {
    if (live) observer.clear_live_progress();
    breakdown_ = e.message() + coupling_advice(net_, solver_.network_boundaries(), e.vessel);
    return RunStatus::broken_down;
  }
  if (plan_.until_periodic && !periodic()) return RunStatus::not_periodic;
  return RunStatus::complete;
}

}  // namespace hemotree
