// The red cells' and tracers' state in a checkpoint and back, bit for bit: per cell, per
// boundary of the network, per vessel and per face, in the one-process grid's order (over
// ranks, solver/flow_transport_ranks.cpp places each rank's share).
#include "solver/flow_transport.hpp"

namespace hemotree {

void FlowTransport::put_red_cells(CheckpointWriter& out, const RedCellState& state) {
  out.section("red cells");
  out.put(state.discharge);
  out.put(state.volume);
  out.put(state.entered);
  out.put(state.left);
  out.put(state.adjusted);
  out.put(state.last_outflow);
  out.put(state.applied);  // the factors themselves are the solver's (its checkpoint)
  out.put(state.faces);    // the last step's flow directions: which node a 0D probe reads (cell_at)
}

FlowTransport::RedCellState FlowTransport::get_red_cells(CheckpointReader& in) const {
  in.section("red cells");
  RedCellState s;
  s.discharge = in.get_vector();
  s.volume = in.get_vector();
  s.entered = in.get_vector();
  s.left = in.get_vector();
  s.adjusted = in.get_double();
  s.last_outflow = in.get_vector();
  const std::size_t boundaries = solver_.boundary_list().size();
  if (s.discharge.size() != cell_count() || s.volume.size() != cell_count() || s.entered.size() != boundaries ||
      s.left.size() != boundaries || s.last_outflow.size() != boundaries)
    in.fail("red cells of another network or another transport grid");
  s.applied = in.get_vector();
  if (s.applied.size() != (options_.viscosity_feedback ? net_.vessel_count() : 0))
    in.fail("red-cell viscosities of another network");
  // Without them a probe in a 0D vessel read the other node until the next transport step
  // (4 samples after a resume differed from the uninterrupted run's).
  s.faces = in.get_vector();
  if (s.faces.size() != (cut_ ? cut_->faces : face_volume_.size()))
    in.fail("red-cell faces of another network or another transport grid");
  return s;
}

void FlowTransport::save(CheckpointWriter& out) const {
  const RedCellTransport& t = *red_cells_;
  put_red_cells(out, {{t.discharge_hematocrit().begin(), t.discharge_hematocrit().end()},
                      {t.volume().begin(), t.volume().end()},
                      t.entered_by_boundary(),
                      t.left_by_boundary(),
                      t.adjusted(),
                      t.last_outflow(),
                      applied_hematocrit_,
                      {face_volume_.begin(), face_volume_.end()}});
  out.put(static_cast<std::uint64_t>(advances_));
  out.put(last_time_);
  for (std::size_t k = 0; k < tracers_.size(); ++k) {
    const TracerTransport& t = tracers_[k];
    put_tracer(out, {{t.concentration().begin(), t.concentration().end()},
                     t.last_outflow(),
                     t.entered_by_boundary(),
                     t.left_by_boundary(),
                     t.injected(),
                     t.adjusted(),
                     curves_[k].state()});
  }
}

void FlowTransport::put_tracer(CheckpointWriter& out, const TracerState& state) {
  out.put(state.concentration);
  out.put(state.last_outflow);
  out.put(state.entered);
  out.put(state.left);
  out.put(std::vector<double>{state.injected, state.adjusted});
  out.put(state.curve);
}

FlowTransport::TracerState FlowTransport::get_tracer(CheckpointReader& in, std::size_t k) const {
  TracerState s;
  s.concentration = in.get_vector();
  s.last_outflow = in.get_vector();
  s.entered = in.get_vector();
  s.left = in.get_vector();
  const std::vector<double> totals = in.get_vector();
  s.curve = in.get_vector();
  const std::size_t boundaries = solver_.boundary_list().size();
  if (s.concentration.size() != cell_count() || s.last_outflow.size() != boundaries || s.entered.size() != boundaries ||
      s.left.size() != boundaries || totals.size() != 2 || s.curve.size() != IndicatorCurves::state_arrays * net_.vessel_count())
    in.fail("tracer " + options_.tracers[k].name + " of another network or transport grid");
  s.injected = totals[0];
  s.adjusted = totals[1];
  return s;
}

void FlowTransport::restore(CheckpointReader& in) {
  RedCellState s = get_red_cells(in);
  applied_hematocrit_ = std::move(s.applied);
  if (cut_) {
    restore_share(s);
  } else {
    red_cells_->restore(s.discharge, s.volume, s.entered, s.left, s.adjusted, s.last_outflow);
    std::copy(s.faces.begin(), s.faces.end(), face_volume_.begin());
  }
  advances_ = static_cast<std::size_t>(in.get_u64());
  last_time_ = in.get_double();
  for (std::size_t k = 0; k < tracers_.size(); ++k) {
    const TracerState t = get_tracer(in, k);
    curves_[k].restore(t.curve);
    if (cut_) restore_tracer_share(k, t);
    else tracers_[k].restore(t.concentration, t.last_outflow, t.entered, t.left, t.injected, t.adjusted);
  }
  mark();
  begin_cycle();
}

}  // namespace hemotree
