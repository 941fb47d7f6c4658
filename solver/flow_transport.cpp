#include "solver/flow_transport.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <utility>

#include "core/errors.hpp"
#include "core/setting_error.hpp"
#include "physics/rheology.hpp"

namespace hemotree {

FlowTransportOptions red_cells_fixed(FlowTransportOptions options) {
  options.red_cells = options.phase_separation = options.fahraeus = options.viscosity_feedback = false;
  return options;
}

FlowTransport::FlowTransport(const Network& net, PulseSolver& solver, FlowTransportOptions options,
                             const TransportRanks* ranks)
    : net_(net), solver_(solver), options_(options) {
  if (solver.steps() != 0)
    throw InputError("red-cell transport: set up before the solver's first step (its face volumes start then)");
  const LumpedVessels& lumped = solver.lumped();
  // Its cells at 0D nodes are the network's nodes: the inner nodes of a vessel in sections
  // would hold volume no cell does (solver_options() keeps every 0D vessel one section).
  if (lumped.sectioned())
    throw InputError("red-cell and tracer transport: the 0D vessels must be one pi section each (--lumped-sections 1)");
  solver_.track_face_volumes();
  const RunBoundaries& boundaries = solver.boundary_list();
  const Blood blood = solver.blood();

  TransportGrid grid;
  // Over ranks a cut per root vessel: on a share its own roots, on the top's rank its ghosts.
  const std::vector<std::int32_t> no_roots;
  const std::vector<std::int32_t>& roots = ranks ? lumped.root_vessels() : no_roots;
  grid.cuts = roots.size();
  grid.boundaries = boundaries.size() + grid.cuts;
  if (ranks) {
    cut_.emplace();
    cut_->run_boundaries = boundaries.size();
    cut_->roots.face.assign(roots.size(), -1);
    cut_->roots.cell.assign(roots.size(), -1);
    cut_->roots.across.assign(roots.size(), -1);
    cut_->roots.far.assign(roots.size(), blood.hematocrit);
    cut_->roots.ghost.assign(lumped.empty() ? 0 : lumped.network_node_count(), -1);
    if (solver.one_d_spread()) cut_->spread.emplace();
  }
  std::vector<double> volume;
  add_node_cells(grid, volume);
  const EndSides sides = add_one_d_cells(grid, volume);
  const EndFaces end_faces = add_faces(grid, roots, sides);

  inflow_hematocrit_.assign(grid.boundaries, blood.hematocrit);  // a cut's: given every step
  for (std::size_t b = 0; b < boundaries.size(); ++b) inflow_hematocrit_[b] = boundaries[b].entering_hematocrit(blood);
  solver_volumes(volume);
  red_cells_.emplace(std::move(grid), std::move(volume), blood.hematocrit,
                     RedCellOptions{options_.phase_separation, blood.phase_separation_diameter_scale()});
  face_volume_ = red_cells_->face_volumes();
  // A vessel's sums over its faces are taken run by run (close_step, follow_curve).
  if (!red_cells_->grid().faces_by_vessel())
    throw std::logic_error("red-cell transport: a vessel's faces are not one after another in the grid");
  if (cut_ && cut_->spread) place_spread_cut(end_faces);
  else if (ranks) place_cut(*ranks);
  const std::size_t vessels = net.vessel_count();
  cycle_cells_.assign(vessels, 0.0);
  cycle_blood_.assign(vessels, 0.0);
  cycle_low_.assign(vessels, 0.0);
  cycle_high_.assign(vessels, 0.0);
  if (options_.viscosity_feedback) {
    applied_hematocrit_.assign(vessels, blood.hematocrit);
    viscosity_scaling_.reserve(vessels);
    for (std::size_t v = 0; v < vessels; ++v) viscosity_scaling_.emplace_back(blood, net.mean_diameter(v));
  }
  set_up_tracers();
  last_time_ = solver.time();
  mark();
  if (!cut_) begin_cycle();  // over ranks in join_ranks, the constructor taking no collective call
}

void FlowTransport::set_up_tracers() {
  // Tracers: clean blood at every boundary that lets blood in, what left at the others.
  const RunBoundaries& boundaries = solver_.boundary_list();
  const LumpedVessels& lumped = solver_.lumped();
  const TransportGrid& carried = red_cells_->grid();
  for (const TracerSpec& spec : options_.tracers) {
    tracers_.emplace_back(carried.cell_count(), carried.boundaries, spec.carrier);
    curves_.emplace_back(net_.vessel_count(), spec.concentration, spec.centre(), spec.shape == TracerSpec::Shape::step);
    std::vector<std::int32_t> given;
    std::int32_t face = -1;
    if (spec.place == TracerSpec::Place::vessel) {
      // Over ranks the rank that steps the vessel injects (the top's ghost of a share's root
      // vessel does not: what crosses the cut carries the injection already, or takes it there).
      const auto v = static_cast<std::size_t>(spec.at);
      if (one_d_place(v) >= 0) face = vessel_first_face_[static_cast<std::size_t>(one_d_place(v))];
      else if (solver_.is_lumped(v) && solver_.steps_vessel(v))
        face = lumped_face_[static_cast<std::size_t>(lumped.vessel_index(v))];
    } else {
      for (std::size_t b = 0; b < boundaries.size(); ++b) {
        if (!boundaries.is_outlet(b) && (spec.place == TracerSpec::Place::inlet || boundaries.node(b) == spec.at))
          given.push_back(static_cast<std::int32_t>(b));
      }
      if (given.empty())
        throw SettingError("tracer", placeholder("tracer") + " " + spec.name + ": " +
                           (spec.place == TracerSpec::Place::inlet
                                ? std::string("the network has no flow or pressure boundary to give it through")
                                : "node " + std::to_string(net_.node_id[static_cast<std::size_t>(spec.at)]) +
                                      " has no flow or pressure boundary (at=vessel:ID gives it inside the network)"));
    }
    tracer_boundaries_.push_back(std::move(given));
    tracer_face_.push_back(face);
  }
  tracer_inflow_.resize(tracers_.size());
  tracer_injected_.resize(tracers_.size());
  if (cut_) cut_->roots.tracer_far.assign(tracers_.size() * cut_->roots.face.size(), 0.0);
}

void FlowTransport::tracer_given(std::size_t k, double t0, double t1) {
  const RunBoundaries& boundaries = solver_.boundary_list();
  const TransportGrid& grid = red_cells_->grid();
  const double given = options_.tracers[k].mean_over(t0, t1);
  std::vector<double>& inflow = tracer_inflow_[k];
  inflow.assign(grid.boundaries, 0.0);  // a cut's from the messages (over ranks)
  for (std::size_t b = 0; b < boundaries.size(); ++b)
    if (boundaries.is_outlet(b)) inflow[b] = std::numeric_limits<double>::quiet_NaN();  // an outlet returns what it took
  for (const std::int32_t b : tracer_boundaries_[k]) inflow[static_cast<std::size_t>(b)] = given;
  tracer_injected_[k] = tracer_face_[k] >= 0 ? Injection{static_cast<std::size_t>(tracer_face_[k]), given} : Injection{};
}

void FlowTransport::follow_curve(std::size_t k, double t0, double t1) {
  // Each vessel's curve: the mean over its faces that passed blood of what crossed them.
  const TransportGrid& grid = red_cells_->grid();
  const TracerTransport& tracer = tracers_[k];
  for (std::size_t f = 0; f < grid.face_count();) {
    const std::size_t end = grid.vessel_faces_end(f);
    const std::int32_t v = grid.vessel[f];
    if (v < 0) {
      f = end;
      continue;
    }
    double sum = 0;
    int count = 0;
    for (; f < end; ++f) {
      if (face_volume_[f] == 0) continue;
      sum += tracer.inflowing(f, *red_cells_, tracer_inflow_[k], tracer_injected_[k]);
      ++count;
    }
    if (count > 0) curves_[k].add(static_cast<std::size_t>(v), t0, t1, sum / count);
  }
}

void FlowTransport::step_tracers(double t0, double t1) {
  for (std::size_t k = 0; k < tracers_.size(); ++k) {
    tracer_given(k, t0, t1);
    tracers_[k].step(*red_cells_, tracer_inflow_[k], tracer_injected_[k]);
    follow_curve(k, t0, t1);
  }
}

std::size_t FlowTransport::bytes() const {
  std::size_t total = red_cells_->bytes() + sizeof(double) * static_cast<std::size_t>(slice_integral_.size() + boundary_mark_.size()) +
                      arrays_bytes(vessel_first_cell_, vessel_first_face_, proximal_sign_, lumped_face_, one_d_, one_d_by_vessel_,
                                   inflow_hematocrit_, slice_volume_, cycle_cells_, cycle_blood_, cycle_low_, cycle_high_,
                                   applied_hematocrit_, viscosity_scaling_, tracer_face_, tracer_injected_);
  for (std::size_t k = 0; k < tracers_.size(); ++k)
    total += tracers_[k].bytes() + curves_[k].bytes() + arrays_bytes(tracer_boundaries_[k], tracer_inflow_[k]);
  if (cut_) {
    const Cut& c = *cut_;
    total += arrays_bytes(c.cell_place, c.face_place, c.face_sign, c.copies, c.roots.face, c.roots.cell, c.roots.across,
                          c.roots.far, c.roots.tracer_far, c.roots.ghost);
    if (c.spread) {
      total += array_bytes(c.spread->tracer_in);
      for (const Cut::Links::Neighbour& n : c.spread->neighbours)
        total += arrays_bytes(n.send_face, n.send_cell, n.receive_face, n.send_volume, n.receive_volume, n.receive_cell);
    }
  }
  return total;
}

FlowTransport::TracerReport FlowTransport::tracer_report(std::size_t k) const {
  const TracerTransport& t = tracers_[k];
  return {curves_[k].landmarks(solver_.time()), t.amount(*red_cells_), t.entered(), t.left(), t.injected(), t.adjusted()};
}

FlowTransport::Outcome FlowTransport::take_outcome() {
  Outcome o{options_.tracers, {}, options_.red_cells, solver_.blood().pries_diameter_scale(), cell_count(), advances_};
  if (cut_) {
    o.reports = std::move(reports_);
  } else {
    for (std::size_t k = 0; k < tracers_.size(); ++k) o.reports.push_back(tracer_report(k));
  }
  return o;
}

std::size_t FlowTransport::cell_at(std::size_t v, double x) const {
  if (const std::int32_t i = one_d_place(v); i >= 0) {
    const int count = solver_.elements_per_vessel() * slices_;
    const int k = std::clamp(static_cast<int>(x * count), 0, count - 1);
    return static_cast<std::size_t>(vessel_first_cell_[static_cast<std::size_t>(i)] + k);
  }
  const LumpedVessels& lumped = solver_.lumped();
  const std::int32_t i = lumped.vessel_index(v);
  const auto face = static_cast<std::size_t>(lumped_face_[static_cast<std::size_t>(i)]);
  const double q = cut_ ? cut_->face_sign[face] * face_volume_[face] : face_volume_[face];
  const bool from = q != 0 ? q > 0 : x < 0.5;
  return static_cast<std::size_t>(from ? lumped.from_node(i) : lumped.to_node(i));
}

double FlowTransport::hematocrit_at(std::size_t v, double x) const {
  const std::size_t c = cell_at(v, x);
  // Over ranks a root vessel's node across the cut: its hematocrit as the last step sent it.
  if (cut_ && c < cut_->roots.ghost.size() && cut_->roots.ghost[c] >= 0) return cut_->roots.far[static_cast<std::size_t>(cut_->roots.ghost[c])];
  return red_cells_->discharge_hematocrit()[c];
}

double FlowTransport::tracer_at(std::size_t k, std::size_t v, double x) const {
  const std::size_t c = cell_at(v, x);
  if (cut_ && c < cut_->roots.ghost.size() && cut_->roots.ghost[c] >= 0)
    return cut_->roots.tracer_far[k * cut_->roots.face.size() + static_cast<std::size_t>(cut_->roots.ghost[c])];
  return tracers_[k].concentration()[c];
}

bool FlowTransport::empty_node_cell(std::size_t c) const {
  if (!cut_ || c >= cut_->roots.ghost.size()) return false;  // (sized to the node cells in either layout)
  return cut_->roots.ghost[c] >= 0 || (solver_.lumped().halo() && solver_.lumped().ghost_node(static_cast<std::int32_t>(c)));
}

void FlowTransport::solver_volumes(std::vector<double>& volume) const {
  const LumpedVessels& lumped = solver_.lumped();
  if (!lumped.empty())
    for (std::size_t k = 0; k < lumped.network_node_count(); ++k)  // a node across a cut holds none here
      volume[k] = empty_node_cell(k) ? 0.0 : lumped.stored_volume(static_cast<std::int32_t>(k));
  slice_volumes(volume, 0);
}

void FlowTransport::slice_volumes(std::span<double> volume, std::size_t first) const {
  const Eigen::MatrixXd& area = solver_.state().area;
  const std::vector<std::int32_t>& one_d = one_d_;
  for (std::size_t i = 0; i < one_d.size(); ++i) {
    auto cell = static_cast<std::size_t>(vessel_first_cell_[i]) - first;
    const auto first_element = solver_.first_element(static_cast<std::size_t>(one_d[i]));
    for (auto el = first_element; el < first_element + solver_.elements_per_vessel(); ++el) {
      const double half = solver_.element_half_length(static_cast<std::size_t>(el));
      for (int s = 0; s < slices_; ++s)
        volume[cell++] = half * slice_integral_.row(s).dot(area.row(el).head(slice_integral_.cols()));
    }
  }
}

void FlowTransport::mark() {
  solver_.clear_face_volumes();
  boundary_mark_ = solver_.boundary_volumes();
}

void FlowTransport::restart() {
  last_time_ = solver_.time();
  mark();
}

void FlowTransport::take_volumes() {
  std::vector<double> now(red_cells_->volume().begin(), red_cells_->volume().end());
  solver_volumes(now);
  // Each tracer's carrier moves with the volumes: what that adds, cell by cell.
  const std::size_t cells = now.size();
  std::vector<std::vector<double>> carried_before(tracers_.size(), std::vector<double>(cells));
  for (std::size_t k = 0; k < tracers_.size(); ++k)
    for (std::size_t c = 0; c < cells; ++c) carried_before[k][c] = tracers_[k].carried(*red_cells_, c);
  // Over ranks, what it adds cell by cell, summed in the one-process order
  // (RedCellTransport::set_volumes' own sum is a share's).
  const double adjusted_before = red_cells_->adjusted();
  std::vector<double> added(cut_ ? now.size() : 0);
  for (std::size_t c = 0; c < added.size(); ++c) added[c] = (now[c] - red_cells_->volume()[c]) * red_cells_->tube_hematocrit(c);
  red_cells_->set_volumes(now);
  if (cut_) red_cells_->set_adjusted(cell_sum(added, adjusted_before));  // rank 0's the whole's
  for (std::size_t k = 0; k < tracers_.size(); ++k) {
    TracerTransport& t = tracers_[k];
    std::vector<double>& added = carried_before[k];
    for (std::size_t c = 0; c < cells; ++c) added[c] = (t.carried(*red_cells_, c) - added[c]) * t.concentration()[c];
    t.set_adjusted(cell_sum(added, t.adjusted()));  // over ranks rank 0's the whole's
  }
}

double FlowTransport::cell_sum(std::span<const double> per_cell, double start) const {
  if (cut_) return lead_sum(per_cell, own_cell_places(), cut_->cells, start);
  return std::accumulate(per_cell.begin(), per_cell.end(), start);
}

FlowTransport::Totals FlowTransport::totals() const {
  const RedCellTransport& t = *red_cells_;
  if (!cut_) return {t.red_cells(), t.entered(), t.left(), t.adjusted()};
  std::vector<double> content(t.grid().cell_count());
  for (std::size_t c = 0; c < content.size(); ++c) content[c] = t.content(c);
  const std::vector<std::int32_t> held = boundary_places();
  return {cell_sum(content, 0.0),
          lead_sum(t.entered_by_boundary(), held, cut_->run_boundaries, 0.0),
          lead_sum(t.left_by_boundary(), held, cut_->run_boundaries, 0.0), t.adjusted()};
}

void FlowTransport::face_volumes() {
  const PulseState& s = solver_.state();
  const LumpedVessels& lumped = solver_.lumped();
  for (std::size_t i = 0; i < lumped_face_.size(); ++i) {
    const auto face = static_cast<std::size_t>(lumped_face_[i]);
    const double passed = lumped.passed_volume(static_cast<std::int32_t>(i));
    face_volume_[face] = cut_ ? cut_->face_sign[face] * passed : passed;
  }
  // The boundaries at 0D nodes: faces one after another, each to its boundary.
  const TransportGrid& grid = red_cells_->grid();
  const auto [first_boundary_face, boundary_faces] = node_boundary_faces_;
  for (auto f = static_cast<std::size_t>(first_boundary_face); f < static_cast<std::size_t>(first_boundary_face + boundary_faces); ++f) {
    const auto b = static_cast<std::size_t>(-1 - grid.b[f]);
    face_volume_[f] = -(solver_.boundary_volume(b) - boundary_mark_(static_cast<Eigen::Index>(b)));
  }
  // 1D vessels: the proximal face's volume, then each slice's change passed on. Their
  // slices' volumes alone (not the 0D nodes', which no face here reads), from the first.
  const std::vector<std::int32_t>& one_d = one_d_;
  const int cells_per_vessel = solver_.elements_per_vessel() * slices_;
  const std::size_t first = one_d.empty() ? 0 : static_cast<std::size_t>(vessel_first_cell_.front());
  slice_volume_.resize(one_d.empty() ? 0 : static_cast<std::size_t>(vessel_first_cell_.back() + cells_per_vessel) - first);
  slice_volumes(slice_volume_, first);
  const std::span<const double> held = red_cells_->volume();
  for (std::size_t i = 0; i < one_d.size(); ++i) {
    const auto el = solver_.first_element(static_cast<std::size_t>(one_d[i]));
    double passed = s.faces(el);
    auto face = static_cast<std::size_t>(vessel_first_face_[i]);
    face_volume_[face++] = proximal_sign_[i] * passed;
    for (int c = 0; c < cells_per_vessel; ++c) {
      const auto cell = static_cast<std::size_t>(vessel_first_cell_[i] + c);
      passed -= slice_volume_[cell - first] - held[cell];
      face_volume_[face++] = passed;
    }
  }
}

void FlowTransport::advance() {
  face_volumes();
  if (cut_ && cut_->spread) {
    advance_spread();
  } else if (cut_) {
    advance_over_ranks();
  } else {
    red_cells_->step(face_volume_, inflow_hematocrit_);
    ++advances_;
    mark();
    step_tracers(last_time_, solver_.time());
    last_time_ = solver_.time();
  }
  close_step();
}

void FlowTransport::close_step() {
  // The cycle's sums per vessel: red cells and blood through its faces, and the step's
  // discharge hematocrit (the faces' mean) for its extremes.
  const TransportGrid& grid = red_cells_->grid();
  const std::span<const double> cells = red_cells_->cells_through();
  for (std::size_t f = 0; f < grid.face_count();) {
    const std::size_t end = grid.vessel_faces_end(f);
    const std::int32_t v = grid.vessel[f];
    // Another rank's 1D vessel, its end here. (A 0D vessel in a halo is followed as its own
    // rank follows it, from the same bits: its viscosity enters this rank's rows too.)
    if (v < 0 || (cut_ && cut_->spread && !solver_.steps_vessel(static_cast<std::size_t>(v)) &&
                  !solver_.is_lumped(static_cast<std::size_t>(v)))) {
      f = end;
      continue;
    }
    const auto vi = static_cast<std::size_t>(v);
    double sum = 0;
    int count = 0;
    for (; f < end; ++f) {
      const double q = face_volume_[f];
      if (q == 0) continue;
      cycle_cells_[vi] += std::abs(cells[f]);
      cycle_blood_[vi] += std::abs(q);
      sum += cells[f] / q;
      ++count;
    }
    if (count == 0) continue;
    const double h = sum / count;
    cycle_low_[vi] = std::min(cycle_low_[vi], h);
    cycle_high_[vi] = std::max(cycle_high_[vi], h);
    if (options_.viscosity_feedback) follow_viscosities(vi, h);
  }
}

void FlowTransport::begin_cycle() {
  std::fill(cycle_cells_.begin(), cycle_cells_.end(), 0.0);
  std::fill(cycle_blood_.begin(), cycle_blood_.end(), 0.0);
  std::fill(cycle_low_.begin(), cycle_low_.end(), std::numeric_limits<double>::infinity());
  std::fill(cycle_high_.begin(), cycle_high_.end(), -std::numeric_limits<double>::infinity());
  const Totals now = totals();
  cycle_content_ = now.red_cells;
  cycle_entered_ = now.entered;
  cycle_left_ = now.left;
  cycle_adjusted_ = now.adjusted;
}

RedCellCycle FlowTransport::close_cycle() const {
  RedCellCycle c;
  const std::size_t vessels = cycle_cells_.size();
  c.discharge.resize(vessels);
  c.lowest.resize(vessels);
  c.highest.resize(vessels);
  for (std::size_t v = 0; v < vessels; ++v) {
    // A vessel no blood went through in the whole cycle holds plasma (the steady rule).
    c.discharge[v] = cycle_blood_[v] > 0 ? cycle_cells_[v] / cycle_blood_[v] : 0.0;
    c.lowest[v] = std::isfinite(cycle_low_[v]) ? cycle_low_[v] : 0.0;
    c.highest[v] = std::isfinite(cycle_high_[v]) ? cycle_high_[v] : 0.0;
  }
  const Totals now = totals();
  c.red_cells = now.red_cells;
  c.entered = now.entered - cycle_entered_;
  c.left = now.left - cycle_left_;
  const double adjusted = now.adjusted - cycle_adjusted_;
  c.balance_error = (c.red_cells - cycle_content_ - (c.entered - c.left) - adjusted) /
                    std::max(cycle_content_ + c.entered, std::numeric_limits<double>::min());
  c.separating_nodes = red_cells_->separating_nodes();
  if (cut_) close_cycle_over_ranks(c);
  return c;
}

void FlowTransport::follow_viscosities(std::size_t v, double hematocrit) {
  if (std::abs(hematocrit - applied_hematocrit_[v]) <= options_.viscosity_tolerance) return;
  // The Pries viscosity at this hematocrit over the run's, at the vessel's reference lumen.
  solver_.set_viscosity_factor(v, viscosity_scaling_[v](hematocrit));
  applied_hematocrit_[v] = hematocrit;
}

}  // namespace hemotree
