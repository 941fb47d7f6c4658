// PulseSolver's state written to a checkpoint and read back bit for bit (formats/checkpoint_file.hpp):
// what evolves (solution, multistep history, junction guesses, compliance balance marks,
// viscosity factors, time); the rest is rebuilt from the network and the options. Over ranks
// the same bytes, written by the lead rank (the top's) with every rank's share of the 0D
// vessels and boundaries, and read by each rank for its share.
#include <algorithm>
#include <array>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "pulse/pulse_solver.hpp"

namespace hemotree {

void PulseSolver::save(CheckpointWriter& out) const {
  save_section(out, lumped_boundary_volume_, viscosity_factor_,
               {&state_, &previous_rate_, &previous_flow_,
                [this](std::size_t v, bool distal) { return boundaries_.state_at(vessel_end(v, distal)); }});
  lumped_.save(out);
}

void PulseSolver::save_over_ranks(CheckpointWriter* out) const {
  if (out && !one_d_here_) throw std::logic_error("PulseSolver::save_over_ranks: written where the top is not");
  // Each boundary's volume from the rank that holds it (the others' entries are not theirs).
  std::vector<double> boundary_volume = lumped_boundary_volume_;
  std::vector<unsigned char> held(boundary_volume.size(), 0);
  for (const std::int32_t b : held_boundaries()) held[static_cast<std::size_t>(b)] = 1;
  lead_whole_(boundary_volume, held);
  // The viscosity factors (a red-cell transport's): each vessel's from the rank that steps it,
  // none where no rank has set any (as the one-process run has none until a vessel's is set).
  std::vector<double> set_on(static_cast<std::size_t>(rank_count_), 0.0);
  std::vector<unsigned char> own(set_on.size(), 0);
  set_on[static_cast<std::size_t>(rank_)] = viscosity_factor_.empty() ? 0.0 : 1.0;
  own[static_cast<std::size_t>(rank_)] = 1;
  make_whole_(set_on, own);  // every rank decides alike: the gather below is collective
  std::vector<double> factors;
  if (std::count(set_on.begin(), set_on.end(), 1.0) > 0) {
    factors = viscosity_factor_.empty() ? std::vector<double>(net_.vessel_count(), 1.0) : viscosity_factor_;
    lead_whole_(factors, steps_vessel_);
  }
  // The 0D state's places: each own node and edge at its place in the whole's order.
  const LumpedVessels::StateShare share = lumped_.state_share(lumped_places(net_, zero_d_));
  // The 1D vessels' state: the top's own, or, spread, from every rank.
  std::optional<WholeOneD> one_d;
  if (one_d_cut_) one_d = whole_one_d_state();
  if (out) {
    if (one_d) {
      // The ends by vessel: the k-th 1D vessel in vessel order is first_elements_[k]'s.
      auto end_state = [&](std::size_t v, bool distal) {
        const auto k = static_cast<std::size_t>(
            std::lower_bound(first_elements_.begin(), first_elements_.end(), std::pair{static_cast<std::int32_t>(v), std::int32_t{-1}}) -
            first_elements_.begin());
        return EndState{one_d->ends[4 * k + (distal ? 2 : 0)], one_d->ends[4 * k + (distal ? 3 : 1)]};
      };
      save_section(*out, boundary_volume, factors, {&one_d->state, &one_d->previous_rate, &one_d->previous_flow, end_state});
    } else {
      save_section(*out, boundary_volume, factors,
                   {&state_, &previous_rate_, &previous_flow_,
                    [this](std::size_t v, bool distal) { return boundaries_.state_at(vessel_end(v, distal)); }});
    }
    LumpedVessels::begin_whole(*out);
  }
  one_d.reset();
  // The 0D arrays one at a time, each whole on the lead alone, written as it comes: every
  // other rank sends its own values (not a whole array of its own), and the lead holds one
  // whole array, not six.
  for (std::size_t a = 0; a < LumpedVessels::state_arrays; ++a) {
    const std::vector<double> whole = lead_places_(lumped_.share_values(a), share.place(a), share.whole(a));
    if (out) out->put(whole);
  }
}

void PulseSolver::save_section(CheckpointWriter& out, const std::vector<double>& lumped_boundary_volume,
                               const std::vector<double>& viscosity_factor, const OneDState& one_d) const {
  out.section("pulse solver");
  out.put(time_);
  out.put(dt_);
  out.put(static_cast<std::uint64_t>(steps_));
  out.put(have_previous_rate_);
  out.put(tracking_faces_);
  for (const PulseState* s : {one_d.state, one_d.previous_rate}) {
    out.put(s->area);
    out.put(s->flow);
    out.put(s->capacitor);
    out.put(s->coupled);
    out.put(s->boundary);
    out.put(s->faces);
  }
  out.put(*one_d.previous_flow);
  out.put(lumped_boundary_volume);
  out.put(cycle_volume_);
  out.put(cycle_capacitor_);
  // The junctions' Newton iterations start from the last end states: per vessel, proximal
  // then distal (area, flow), a 0D vessel's as zeros (the format's layout, which held them),
  // written in pieces of `block` vessels.
  const std::size_t n = net_.vessel_count();
  out.begin_vector(4 * static_cast<std::uint64_t>(n));
  constexpr std::size_t block = 1 << 16;
  std::vector<double> ends;
  ends.reserve(4 * std::min(n, block));
  for (std::size_t first = 0; first < n; first += block) {
    ends.clear();
    for (std::size_t v = first; v < std::min(n, first + block); ++v) {
      for (const bool distal : {false, true}) {
        const EndState e = zero_d_[v] ? EndState{} : one_d.end_state(v, distal);
        ends.push_back(e.area);
        ends.push_back(e.flow);
      }
    }
    out.put_part(ends);
  }
  std::vector<double> rest;
  for (const auto& o : boundaries_.outlets) {
    rest.push_back(o.rest_area);
    rest.push_back(o.rest_flow);
  }
  out.put(rest);
  out.put(viscosity_factor);
}

void PulseSolver::restore(CheckpointReader& in) {
  in.section("pulse solver");
  time_ = in.get_double();
  const double dt = in.get_double();
  if (dt != dt_)
    in.fail("time step " + std::to_string(dt) + " s in the checkpoint, " + std::to_string(dt_) +
            " s in this run: the checkpoint belongs to other options or another network");
  steps_ = static_cast<std::size_t>(in.get_u64());
  have_previous_rate_ = in.get_bool();
  // A run with a transport tracks face volumes from its start; one without tracks none.
  if (in.get_bool() != tracking_faces_)
    in.fail(tracking_faces_ ? "written by a run without red-cell or tracer transport"
                            : "written by a run that transported red cells or tracers (this one does not)");
  in.get_into(state_.area, "areas");
  in.get_into(state_.flow, "flows");
  in.get_into(state_.capacitor, "capacitors");
  in.get_into(state_.coupled, "coupled ends");
  in.get_into(state_.boundary, "boundary volumes");
  state_.faces = in.get_eigen_vector();
  // The multistep history: empty until a multistep scheme has taken a step.
  previous_rate_.area = in.get_matrix();
  previous_rate_.flow = in.get_matrix();
  previous_rate_.capacitor = in.get_eigen_vector();
  previous_rate_.coupled = in.get_eigen_vector();
  previous_rate_.boundary = in.get_eigen_vector();
  previous_rate_.faces = in.get_eigen_vector();
  if (tracking_faces_ && state_.faces.size() != state_.area.rows()) in.fail("face volumes of another discretisation");
  if (previous_rate_.area.size() != 0 &&
      (previous_rate_.area.rows() != state_.area.rows() || previous_rate_.area.cols() != state_.area.cols() ||
       previous_rate_.flow.rows() != state_.flow.rows() || previous_rate_.capacitor.size() != state_.capacitor.size()))
    in.fail("multistep history of another discretisation");
  previous_flow_ = in.get_matrix();
  std::vector<double> lumped_boundary_volume = in.get_vector();
  if (lumped_boundary_volume.size() != lumped_boundary_volume_.size()) in.fail("boundaries of another network");
  lumped_boundary_volume_ = std::move(lumped_boundary_volume);
  cycle_volume_ = in.get_vector();
  cycle_capacitor_ = in.get_vector();
  // Per outlet, or none where no outlet is RCR (the balance then reads none).
  if (!cycle_capacitor_.empty() && cycle_capacitor_.size() != outlet_count_)
    in.fail("outlets of another network");
  if (rcr_outlets_ && !cycle_volume_.empty() && cycle_capacitor_.size() != outlet_count_)
    in.fail("outlets of another network");
  cycle_marked_ = !cycle_volume_.empty();
  if (!leads()) {  // over ranks the marks are the lead's (compliance_balance.cpp)
    std::vector<double>().swap(cycle_volume_);
    std::vector<double>().swap(cycle_capacitor_);
  }
  const std::vector<double> ends = in.get_vector();
  if (ends.size() != 4 * net_.vessel_count()) in.fail("vessel ends of another network");
  for (std::size_t v = 0; v < net_.vessel_count(); ++v)
    if (!zero_d_[v])
      for (const bool distal : {false, true}) {
        const std::size_t k = 2 * v + (distal ? 1 : 0);
        boundaries_.state_at(vessel_end(v, distal)) = {ends[2 * k], ends[2 * k + 1]};
      }
  const std::vector<double> rest = in.get_vector();
  if (rest.size() != 2 * boundaries_.outlets.size()) in.fail("outlets of another network");
  for (std::size_t k = 0; k < boundaries_.outlets.size(); ++k) {
    boundaries_.outlets[k].rest_area = rest[2 * k];
    boundaries_.outlets[k].rest_flow = rest[2 * k + 1];
  }
  std::vector<double> factors = in.get_vector();
  if (!factors.empty() && factors.size() != net_.vessel_count()) in.fail("viscosity factors of another network");
  set_viscosity_factors(factors);  // before the 0D vessels' resistances are rebuilt
  if (over_ranks()) lumped_.restore_share(in, lumped_places(net_, zero_d_));
  else lumped_.restore(in);
}

}  // namespace hemotree
