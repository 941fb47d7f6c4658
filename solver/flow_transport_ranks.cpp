// Red cells and tracers over MPI ranks (docs/transport.md, "Over MPI ranks"): where each
// rank's cells, faces and boundaries lie in the one-process run's grid, a step's messages
// across the cuts (two for the red cells, two for the tracers), and the cycle's sums, the
// report's and the checkpoint taken on rank 0 in the one-process order.
#include <mpi.h>

#include <algorithm>
#include <functional>

#include "distributed/gather_rows.hpp"
#include "distributed/root_exchange.hpp"
#include "mpi/session.hpp"
#include "pulse/lumped_order.hpp"
#include "solver/cycle_over_ranks.hpp"
#include "solver/flow_transport.hpp"

namespace hemotree {

namespace {
constexpr std::size_t per_root = 2;  // a side's hematocrit H_D and its phase separation share s_f

// A part of a step that may fail on this rank: its failure, to be made every rank's.
std::exception_ptr attempt(const std::function<void()>& part) {
  try {
    part();
  } catch (...) {
    return std::current_exception();
  }
  return nullptr;
}

// A rank's per-boundary arrays (the grid's boundaries, cuts last) from the whole run's: the
// boundaries it holds (held: the boundary, or -1) take their values, the rest nothing in or
// out and `last` as what last left.
struct BoundaryShare {
  std::vector<double> entered, left, last_outflow;
};
BoundaryShare boundary_share(std::span<const std::int32_t> held, std::span<const double> entered,
                             std::span<const double> left, std::span<const double> last_outflow, double last) {
  BoundaryShare share{std::vector<double>(held.size(), 0.0), std::vector<double>(held.size(), 0.0),
                      std::vector<double>(held.size(), last)};
  for (const std::int32_t b : held)
    if (b >= 0) {
      const auto i = static_cast<std::size_t>(b);
      share.entered[i] = entered[i];
      share.left[i] = left[i];
      share.last_outflow[i] = last_outflow[i];
    }
  return share;
}
}  // namespace

FlowTransport::ZeroDPlaces FlowTransport::zero_d_places() const {
  ZeroDPlaces p;
  const std::size_t n = net_.vessel_count();
  p.zero_d.resize(n);
  for (std::size_t v = 0; v < n; ++v) p.zero_d[v] = solver_.is_lumped(v);
  const LumpedOrder whole = subtree_lumped_order(net_, p.zero_d);
  p.nodes = whole.nodes.size();
  p.node_place.assign(net_.node_count(), -1);
  for (std::size_t k = 0; k < whole.nodes.size(); ++k) p.node_place[static_cast<std::size_t>(whole.nodes[k])] = static_cast<std::int32_t>(k);
  p.zero_d_before.assign(n + 1, 0);  // the 0D vessels before each
  for (std::size_t v = 0; v < n; ++v) p.zero_d_before[v + 1] = p.zero_d_before[v] + (p.zero_d[v] ? 1 : 0);
  const RunBoundaries& boundaries = solver_.boundary_list();
  p.boundary_place.assign(boundaries.size(), -1);
  std::int32_t at_zero_d_nodes = 0;
  for (std::size_t b = 0; b < boundaries.size(); ++b)
    if (p.node_place[static_cast<std::size_t>(boundaries.node(b))] >= 0) p.boundary_place[b] = at_zero_d_nodes++;
  p.zero_d_faces = p.zero_d_before[n];
  p.one_d_faces = p.zero_d_faces + at_zero_d_nodes;
  return p;
}

std::int32_t FlowTransport::ZeroDPlaces::face_place(const TransportGrid& grid, std::size_t f) const {
  const std::int32_t v = grid.vessel[f];
  if (v >= 0) return zero_d[static_cast<std::size_t>(v)] ? zero_d_before[static_cast<std::size_t>(v)] : -1;
  return zero_d_faces + boundary_place[static_cast<std::size_t>(-1 - grid.b[f])];
}

void FlowTransport::place_cut(const TransportRanks& ranks) {
  Cut& cut = *cut_;
  cut.roots.top = solver_.holds_one_d();
  cut.roots.exchange = std::make_shared<RootExchange>(MPI_COMM_WORLD, ranks.top_rank, ranks.roots);
  const TransportGrid& grid = red_cells_->grid();
  const LumpedVessels& lumped = solver_.lumped();
  // The one-process grid: the 0D part (zero_d_places), the 1D vessels' slices and junctions
  // after it, all the top's; the top's 1D faces after the 0D part's in the grid's order.
  const ZeroDPlaces whole = zero_d_places();
  const std::size_t here_nodes = lumped.empty() ? 0 : lumped.network_node_count();
  cut.cell_place.resize(grid.cell_count());
  for (std::size_t c = 0; c < grid.cell_count(); ++c)
    cut.cell_place[c] = c < here_nodes ? whole.node_place[static_cast<std::size_t>(grid.node[c])]
                                       : static_cast<std::int32_t>(whole.nodes + (c - here_nodes));
  const std::size_t one_d_cells = grid.cell_count() - here_nodes;
  std::int32_t first_one_d_face = -1;
  cut.face_place.assign(grid.face_count(), -1);
  for (std::size_t f = 0; f < grid.face_count(); ++f) {
    cut.face_place[f] = whole.face_place(grid, f);
    if (cut.face_place[f] >= 0) continue;
    if (first_one_d_face < 0) first_one_d_face = static_cast<std::int32_t>(f);
    cut.face_place[f] = whole.one_d_faces + (static_cast<std::int32_t>(f) - first_one_d_face);
  }
  // The whole run's counts: every rank knows its 0D part; the top's 1D cells and faces are
  // the top's alone (said to every rank by join_ranks).
  cut.cells = whole.nodes + (cut.roots.top ? one_d_cells : 0);
  cut.faces = static_cast<std::size_t>(whole.one_d_faces) +
              (cut.roots.top && first_one_d_face >= 0 ? grid.face_count() - static_cast<std::size_t>(first_one_d_face) : 0);
}

void FlowTransport::join_ranks() {
  // The top's counts (the others hold their 0D part's, which is every rank's), then the first
  // cycle's sums.
  unsigned long long counts[2] = {cut_->cells, cut_->faces};
  MPI_Allreduce(MPI_IN_PLACE, counts, 2, MPI_UNSIGNED_LONG_LONG, MPI_MAX, MPI_COMM_WORLD);
  cut_->cells = static_cast<std::size_t>(counts[0]);
  cut_->faces = static_cast<std::size_t>(counts[1]);
  begin_cycle();
}

std::vector<std::int32_t> FlowTransport::own_cell_places() const {
  std::vector<std::int32_t> place = cut_->cell_place;
  for (const std::int32_t c : cut_->roots.across) place[static_cast<std::size_t>(c)] = -1;
  for (const std::int32_t c : cut_->copies) place[static_cast<std::size_t>(c)] = -1;
  return place;
}

std::vector<std::int32_t> FlowTransport::own_face_places() const {
  std::vector<std::int32_t> place = cut_->face_place;
  if (cut_->spread) {  // an end of another rank's vessel
    for (std::size_t f = 0; f < place.size(); ++f) {
      const std::int32_t v = red_cells_->grid().vessel[f];
      if (v >= 0 && !solver_.steps_vessel(static_cast<std::size_t>(v))) place[f] = -1;
    }
  } else if (cut_->roots.top) {  // its cuts' faces are the shares' root vessels
    for (const std::int32_t f : cut_->roots.face) place[static_cast<std::size_t>(f)] = -1;
  }
  return place;
}

std::vector<std::int32_t> FlowTransport::boundary_places() const {
  const TransportGrid& grid = red_cells_->grid();
  std::vector<std::int32_t> place(grid.boundaries, -1);
  for (std::size_t f = 0; f < grid.face_count(); ++f) {
    if (grid.b[f] >= 0) continue;
    const auto b = static_cast<std::size_t>(-1 - grid.b[f]);
    if (!grid.is_cut(b)) place[b] = static_cast<std::int32_t>(b);
  }
  return place;
}

std::vector<double> FlowTransport::lead_whole(std::span<const double> values, std::span<const std::int32_t> place,
                                              std::size_t whole) const {
  return gather_places(values, place, whole);
}

double FlowTransport::lead_sum(std::span<const double> values, std::span<const std::int32_t> place, std::size_t whole,
                               double start) const {
  double sum = start;
  for (const double v : lead_whole(values, place, whole)) sum += v;
  return sum;
}

void FlowTransport::across_cuts(std::size_t per_root, std::exception_ptr failure, const char* what,
                                const std::function<std::vector<double>()>& here,
                                const std::function<void(std::span<const double>)>& across,
                                const std::function<void()>& rest) {
  Cut& cut = *cut_;
  // Up: the shares' root nodes (what the top's nodes above take where blood flows up).
  bool failed = false;
  const std::vector<double> up = cut.roots.exchange->gather(cut.roots.top ? std::vector<double>() : here(), failure, per_root, failed);
  std::vector<double> down;
  if (cut.roots.top && !failed && !failure) {
    try {
      across(up);
      rest();
      down = here();
    } catch (...) {
      failure = std::current_exception();
    }
  }
  // Down: the top's nodes above the roots; then a share finishes its subtrees below them.
  const std::vector<double> mine = cut.roots.exchange->scatter(down, failure, per_root, what);
  if (cut.roots.top) return;
  across(mine);
  rest();
}

void FlowTransport::advance_over_ranks() {
  Cut& cut = *cut_;
  RedCellTransport& cells = *red_cells_;
  const std::span<const double> hematocrit = cells.discharge_hematocrit();
  const std::size_t roots = cut.roots.face.size();
  // Blood leaving through a cut carries s_f H_D of the cell it leaves; entering, what the
  // other side's cell sends (the product taken as the one-process run takes it).
  auto from_across = [&](std::span<const double> numbers) {
    for (std::size_t j = 0; j < roots; ++j) {
      cut.roots.far[j] = numbers[per_root * j];
      inflow_hematocrit_[cut.run_boundaries + j] = numbers[per_root * j + 1] * numbers[per_root * j];
    }
  };
  auto from_here = [&] {
    std::vector<double> numbers(per_root * roots);
    for (std::size_t j = 0; j < roots; ++j) {
      numbers[per_root * j] = hematocrit[static_cast<std::size_t>(cut.roots.cell[j])];
      numbers[per_root * j + 1] = cells.separation_share(static_cast<std::size_t>(cut.roots.face[j]));
    }
    return numbers;
  };
  cells.begin_step(face_volume_);
  across_cuts(per_root, attempt([&] { cells.solve(face_volume_, inflow_hematocrit_, RedCellTransport::Cells::before_cuts); }),
              "the red cells' step", from_here, from_across,
              [&] { cells.solve(face_volume_, inflow_hematocrit_, RedCellTransport::Cells::after_cuts); });
  cells.end_step(face_volume_, inflow_hematocrit_);
  ++advances_;
  mark();
  if (!tracers_.empty()) step_tracers_over_ranks(last_time_, solver_.time());
  last_time_ = solver_.time();
}

void FlowTransport::step_tracers_over_ranks(double t0, double t1) {
  // The red cells' step is whole: every tracer rides on its carriers, in its split, with two
  // messages of its own (each root's concentration of every tracer up, then down).
  Cut& cut = *cut_;
  const std::size_t roots = cut.roots.face.size(), count = tracers_.size();
  using Cells = RedCellTransport::Cells;
  auto solve = [&](Cells cells) {
    for (std::size_t k = 0; k < count; ++k) tracers_[k].solve(*red_cells_, tracer_inflow_[k], tracer_injected_[k], cells);
  };
  for (std::size_t k = 0; k < count; ++k) {
    tracer_given(k, t0, t1);
    tracers_[k].begin_step(*red_cells_, tracer_inflow_[k], tracer_injected_[k]);
  }
  const std::exception_ptr failure = attempt([&] { solve(Cells::before_cuts); });
  // What crosses each cut from this side (with an injection there, which its rank adds), and
  // what the other side sent as the cuts' inflows (and the far side's concentration).
  auto from_here = [&] {
    std::vector<double> numbers(count * roots);
    for (std::size_t j = 0; j < roots; ++j)
      for (std::size_t k = 0; k < count; ++k)
        numbers[count * j + k] =
            tracers_[k].inflowing(static_cast<std::size_t>(cut.roots.face[j]), *red_cells_, tracer_inflow_[k], tracer_injected_[k]);
    return numbers;
  };
  auto from_across = [&](std::span<const double> numbers) {
    for (std::size_t j = 0; j < roots; ++j)
      for (std::size_t k = 0; k < count; ++k) {
        tracer_inflow_[k][cut.run_boundaries + j] = numbers[count * j + k];
        cut.roots.tracer_far[k * roots + j] = numbers[count * j + k];
      }
  };
  across_cuts(count, failure, "the tracers' step", from_here, from_across, [&] { solve(Cells::after_cuts); });
  for (std::size_t k = 0; k < count; ++k) {
    tracers_[k].end_step(*red_cells_, tracer_inflow_[k], tracer_injected_[k]);
    follow_curve(k, t0, t1);
  }
}

void FlowTransport::close_cycle_over_ranks(RedCellCycle& c) const {
  std::vector<double>* columns[] = {&c.discharge, &c.lowest, &c.highest};
  gather_vessel_values(net_, solver_, columns);
  // A junction held by several ranks counts once, on the rank of its first end.
  unsigned long long separating = c.separating_nodes;
  for (const std::int32_t cell : red_cells_->separating_cells())
    if (std::find(cut_->copies.begin(), cut_->copies.end(), cell) != cut_->copies.end()) --separating;
  MPI_Reduce(world_rank() == 0 ? MPI_IN_PLACE : &separating, &separating, 1, MPI_UNSIGNED_LONG_LONG, MPI_SUM, 0,
             MPI_COMM_WORLD);
  c.separating_nodes = static_cast<std::size_t>(separating);
}

void FlowTransport::save_over_ranks(CheckpointWriter* out) const {
  const RedCellTransport& t = *red_cells_;
  const std::vector<std::int32_t> cells = own_cell_places(), faces = own_face_places(), held = boundary_places();
  const std::size_t boundaries = cut_->run_boundaries;
  std::vector<double> turned(face_volume_.size());  // each face as the whole grid has it
  for (std::size_t f = 0; f < turned.size(); ++f) turned[f] = cut_->face_sign[f] * face_volume_[f];
  const std::vector<std::int32_t> own = own_vessels();
  std::vector<double> applied;
  if (!applied_hematocrit_.empty())
    for (const std::int32_t v : own) applied.push_back(applied_hematocrit_[static_cast<std::size_t>(v)]);
  const RedCellState whole{lead_whole(t.discharge_hematocrit(), cells, cut_->cells),
                           lead_whole(t.volume(), cells, cut_->cells),
                           lead_whole(t.entered_by_boundary(), held, boundaries),
                           lead_whole(t.left_by_boundary(), held, boundaries),
                           t.adjusted(),
                           lead_whole(t.last_outflow(), held, boundaries),
                           lead_whole(applied, own_vessel_places(own, applied_hematocrit_.empty() ? 0 : 1),
                                      applied_hematocrit_.size()),
                           lead_whole(turned, faces, cut_->faces)};
  if (out) {
    put_red_cells(*out, whole);
    out->put(static_cast<std::uint64_t>(advances_));
    out->put(last_time_);
  }
  const std::vector<std::int32_t> curves = own_vessel_places(own, IndicatorCurves::state_arrays);
  for (std::size_t k = 0; k < tracers_.size(); ++k) {
    const TracerTransport& tracer = tracers_[k];
    const TracerState state{lead_whole(tracer.concentration(), cells, cut_->cells),
                            lead_whole(tracer.last_outflow(), held, boundaries),
                            lead_whole(tracer.entered_by_boundary(), held, boundaries),
                            lead_whole(tracer.left_by_boundary(), held, boundaries),
                            rank_sum(tracer.injected()),
                            tracer.adjusted(),
                            lead_whole(curves_[k].state_of(own), curves, IndicatorCurves::state_arrays * net_.vessel_count())};
    if (out) put_tracer(*out, state);
  }
}

std::vector<std::int32_t> FlowTransport::own_vessels() const {
  std::vector<std::int32_t> own;
  for (std::size_t v = 0; v < net_.vessel_count(); ++v)
    if (solver_.steps_vessel(v)) own.push_back(static_cast<std::int32_t>(v));
  return own;
}

std::vector<std::int32_t> FlowTransport::own_vessel_places(std::span<const std::int32_t> own, std::size_t arrays) const {
  const std::size_t n = net_.vessel_count();
  std::vector<std::int32_t> place;
  place.reserve(arrays * own.size());
  for (std::size_t a = 0; a < arrays; ++a)
    for (const std::int32_t v : own) place.push_back(static_cast<std::int32_t>(a * n + static_cast<std::size_t>(v)));
  return place;
}

double FlowTransport::rank_sum(double value) const {
  const std::vector<std::int32_t> place{world_rank()};
  return lead_sum(std::span<const double>(&value, 1), place, static_cast<std::size_t>(world_size()), 0.0);
}

void FlowTransport::restore_tracer_share(std::size_t k, const TracerState& whole) {
  const TransportGrid& grid = red_cells_->grid();
  std::vector<double> concentration(grid.cell_count());
  for (std::size_t c = 0; c < concentration.size(); ++c) concentration[c] = whole.concentration[static_cast<std::size_t>(cut_->cell_place[c])];
  const std::size_t roots = cut_->roots.across.size();
  for (std::size_t j = 0; j < roots; ++j) cut_->roots.tracer_far[k * roots + j] = concentration[static_cast<std::size_t>(cut_->roots.across[j])];
  const BoundaryShare held = boundary_share(boundary_places(), whole.entered, whole.left, whole.last_outflow, 0.0);
  // The injection's and the balance's totals are rank 0's (the whole run's), and what the
  // injecting rank adds from here on: the same sums, in the same order, there.
  const bool injects = tracer_face_[k] >= 0;
  tracers_[k].restore(concentration, held.last_outflow, held.entered, held.left, injects ? whole.injected : 0.0,
                      world_rank() == 0 ? whole.adjusted : 0.0);
}

void FlowTransport::take_reports() {
  if (!cut_) return;
  reports_.clear();
  const std::vector<std::int32_t> held = boundary_places();
  for (std::size_t k = 0; k < tracers_.size(); ++k) {
    const TracerTransport& t = tracers_[k];
    TracerReport r;
    r.landmarks = curves_[k].landmarks(solver_.time());
    std::vector<double>* columns[] = {&r.landmarks.arrival, &r.landmarks.peak_time, &r.landmarks.peak, &r.landmarks.mean_transit};
    gather_vessel_values(net_, solver_, columns);
    std::vector<double> carried(red_cells_->grid().cell_count());
    for (std::size_t c = 0; c < carried.size(); ++c) carried[c] = t.carried(*red_cells_, c) * t.concentration()[c];
    r.amount = cell_sum(carried, 0.0);
    r.entered = lead_sum(t.entered_by_boundary(), held, cut_->run_boundaries, 0.0);
    r.left = lead_sum(t.left_by_boundary(), held, cut_->run_boundaries, 0.0);
    r.injected = rank_sum(t.injected());
    r.adjusted = t.adjusted();
    reports_.push_back(std::move(r));
  }
}

void FlowTransport::restore_share(const RedCellState& whole) {
  RedCellTransport& t = *red_cells_;
  const TransportGrid& grid = t.grid();
  std::vector<double> discharge(grid.cell_count()), volume(grid.cell_count(), 0.0);
  for (std::size_t c = 0; c < discharge.size(); ++c) {
    discharge[c] = whole.discharge[static_cast<std::size_t>(cut_->cell_place[c])];
    volume[c] = empty_node_cell(c) ? 0.0 : whole.volume[static_cast<std::size_t>(cut_->cell_place[c])];
  }
  for (std::size_t j = 0; j < cut_->roots.across.size(); ++j) cut_->roots.far[j] = discharge[static_cast<std::size_t>(cut_->roots.across[j])];
  const BoundaryShare held = boundary_share(boundary_places(), whole.entered, whole.left, whole.last_outflow,
                                           solver_.blood().hematocrit);
  t.restore(discharge, volume, held.entered, held.left, whole.adjusted, held.last_outflow);
  for (std::size_t f = 0; f < face_volume_.size(); ++f)
    face_volume_[f] = cut_->face_sign[f] * whole.faces[static_cast<std::size_t>(cut_->face_place[f])];
}

}  // namespace hemotree
