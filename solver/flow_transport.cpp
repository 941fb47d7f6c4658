#include "solver/flow_transport.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <numbers>
#include <stdexcept>
#include <utility>

#include "core/errors.hpp"
#include "core/setting_error.hpp"
#include "physics/phase_separation.hpp"
#include "physics/rheology.hpp"
#include "pulse/legendre_basis.hpp"

namespace hemotree {

namespace {

// int of P_j over [lo, hi]: with Q_0 = x and Q_j = (P_(j+1) - P_(j-1)) / (2 j + 1), Q_j' = P_j.
double legendre_integral(int j, double lo, double hi) {
  auto antiderivative = [j](double x) {
    return j == 0 ? x : (legendre(j + 1, x) - legendre(j - 1, x)) / (2 * j + 1);
  };
  return antiderivative(hi) - antiderivative(lo);
}

// What a 1D end meets where that is another rank's 0D node (the 1D vessels spread): a cut.
constexpr std::int32_t remote_side = std::numeric_limits<std::int32_t>::min();

// The diameter a face stands for: a tapered vessel's mean.
double mean_diameter(const Network& net, std::size_t v) { return 0.5 * (net.diameter[v] + net.diameter_at_to(v)); }

}  // namespace

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
    for (std::size_t v = 0; v < vessels; ++v) viscosity_scaling_.emplace_back(blood, mean_diameter(net, v));
  }
  set_up_tracers();
  last_time_ = solver.time();
  mark();
  if (!cut_) begin_cycle();  // over ranks in join_ranks, the constructor taking no collective call
}

double FlowTransport::fahraeus(double diameter) const {
  return options_.fahraeus ? fahraeus_parameter(diameter, solver_.blood().pries_diameter_scale()) : 1.0;
}

std::int32_t FlowTransport::one_d_place(std::size_t v) const {
  const auto found = std::lower_bound(one_d_by_vessel_.begin(), one_d_by_vessel_.end(),
                                      std::pair{static_cast<std::int32_t>(v), std::int32_t{-1}});
  return found != one_d_by_vessel_.end() && found->first == static_cast<std::int32_t>(v) ? found->second : -1;
}

void FlowTransport::add_node_cells(TransportGrid& grid, std::vector<double>& volume) const {
  // Nodes of 0D vessels: k weighted by the half-vessels they hold.
  const LumpedVessels& lumped = solver_.lumped();
  const std::size_t lumped_nodes = lumped.empty() ? 0 : lumped.network_node_count();
  std::vector<std::int32_t> network_node(lumped_nodes, -1);
  for (std::size_t n = 0; n < net_.node_count(); ++n)
    if (!lumped.empty() && lumped.node_of(static_cast<std::int64_t>(n)) >= 0)
      network_node[static_cast<std::size_t>(lumped.node_of(static_cast<std::int64_t>(n)))] = static_cast<std::int32_t>(n);
  std::vector<double> k_sum(lumped_nodes, 0.0), weight(lumped_nodes, 0.0);
  for (std::size_t v = 0; v < net_.vessel_count(); ++v) {
    if (!solver_.is_lumped(v)) continue;
    const std::int32_t i = lumped.vessel_index(v);
    if (i < 0) continue;  // another rank's (over ranks)
    const double d = mean_diameter(net_, v), half = 0.125 * std::numbers::pi * d * d * net_.length[v];
    for (const std::int32_t k : {lumped.from_node(i), lumped.to_node(i)}) {
      k_sum[static_cast<std::size_t>(k)] += half * fahraeus(d);
      weight[static_cast<std::size_t>(k)] += half;
    }
  }
  for (std::size_t k = 0; k < lumped_nodes; ++k) {
    grid.add_cell(network_node[k], weight[k] > 0 ? k_sum[k] / weight[k] : 1.0);
    volume.push_back(lumped.stored_volume(static_cast<std::int32_t>(k)));
  }
}

FlowTransport::EndSides FlowTransport::add_one_d_cells(TransportGrid& grid, std::vector<double>& volume) {
  // Slices of the 1D elements. The 1D vessels: every one, or over ranks the top's rank's (a
  // share's solver has their laws and start, but never steps them).
  const PulseSolver& solver = solver_;
  if (solver.holds_one_d()) one_d_ = solver.one_d_vessels();
  slices_ = options_.slices > 0 ? options_.slices : solver.max_degree() + 1;
  const int modes = solver.max_degree() + 1, per_vessel = solver.elements_per_vessel();
  slice_integral_.resize(slices_, std::max(modes, 1));
  for (int s = 0; s < slices_; ++s)
    for (int j = 0; j < slice_integral_.cols(); ++j)
      slice_integral_(s, j) = legendre_integral(j, -1 + 2.0 * s / slices_, -1 + 2.0 * (s + 1) / slices_);
  for (const std::int32_t vi : one_d_) {
    const auto v = static_cast<std::size_t>(vi);
    one_d_by_vessel_.emplace_back(vi, static_cast<std::int32_t>(vessel_first_cell_.size()));
    vessel_first_cell_.push_back(static_cast<std::int32_t>(grid.cell_count()));
    const int count = per_vessel * slices_;
    for (int s = 0; s < count; ++s) {
      const double x = (s + 0.5) / count;
      const double d = net_.diameter[v] + x * (net_.diameter_at_to(v) - net_.diameter[v]);
      grid.add_cell(-1, fahraeus(d));
      volume.push_back(0.0);  // set from the solver's areas (solver_volumes)
    }
  }
  std::sort(one_d_by_vessel_.begin(), one_d_by_vessel_.end());
  // Junctions of 1D vessels, and what meets each 1D end: (vessel, distal) -> cell or boundary.
  const NetworkBoundaries& ends = solver.network_boundaries();
  EndSides end_side;
  const bool spread = cut_ && cut_->spread;
  for (std::size_t j = 0; j + 1 < ends.junction_offset.size() && solver.holds_one_d(); ++j) {
    const std::span<const VesselEnd> at(ends.junction_ends.data() + ends.junction_offset[j],
                                        static_cast<std::size_t>(ends.junction_offset[j + 1] - ends.junction_offset[j]));
    // Spread: the junctions where this rank has an end, each numbered by the rank of its first.
    if (spread && std::none_of(at.begin(), at.end(), [&](const VesselEnd& e) { return solver.steps_vessel(static_cast<std::size_t>(e.vessel)); })) continue;
    const auto cell = static_cast<std::int32_t>(grid.cell_count());
    const auto v = static_cast<std::size_t>(at[0].vessel);
    if (spread && !solver.steps_vessel(v)) cut_->copies.push_back(cell);
    grid.add_cell(at[0].distal ? net_.to[v] : net_.from[v], 1.0);
    volume.push_back(0.0);
    for (const VesselEnd& end : at) end_side[{end.vessel, end.distal}] = cell;
  }
  // A 0D node another rank holds (the 1D vessels spread): a cut.
  for (const auto& c : ends.coupled) {
    const LumpedVessels& lumped = solver.lumped();
    const std::int32_t node = lumped.empty() ? -1 : lumped.node_of(c.node);
    end_side[{c.end.vessel, c.end.distal}] = node >= 0 && !lumped.ghost_node(node) ? node : remote_side;
  }
  for (const auto* given : {&ends.flows, &ends.pressures})
    for (const auto& g : *given) end_side[{g.end.vessel, g.end.distal}] = TransportGrid::boundary_side(static_cast<std::size_t>(g.index));
  for (const auto& o : ends.outlets)
    end_side[{o.end.vessel, o.end.distal}] = TransportGrid::boundary_side(static_cast<std::size_t>(o.boundary));
  return end_side;
}

FlowTransport::EndFaces FlowTransport::add_faces(TransportGrid& grid, const std::vector<std::int32_t>& roots,
                                                 const EndSides& end_side) {
  const LumpedVessels& lumped = solver_.lumped();
  const RunBoundaries& boundaries = solver_.boundary_list();
  auto side_of = [&](std::int32_t v, bool distal) {
    const auto found = end_side.find({v, distal});
    if (found == end_side.end())
      throw InputError("red-cell transport: vessel " + std::to_string(net_.id[static_cast<std::size_t>(v)]) + ": its " +
                       (distal ? "distal" : "proximal") + " end meets neither a vessel nor a boundary");
    return found->second;
  };
  std::vector<std::int32_t> root_of;  // per 0D vessel here: its root's place in `roots`, or -1
  if (cut_) {
    root_of.assign(lumped.vessel_count(), -1);
    for (std::size_t j = 0; j < roots.size(); ++j) root_of[static_cast<std::size_t>(roots[j])] = static_cast<std::int32_t>(j);
    cut_->face_sign.clear();
  }
  auto new_cut = [&grid] {
    ++grid.cuts;
    return TransportGrid::boundary_side(grid.boundaries++);
  };
  EndFaces end_faces;  // spread: per end, its face here and the cell on this side
  // Faces: the 0D vessels, the boundaries at 0D nodes, then each 1D vessel's. Over ranks a
  // root vessel's joins the node on this side to its cut (turned round where that node is its
  // `to` node); the node across, held for the flow's sums alone, is an empty cell of no face.
  // A 0D system spread with a halo: a vessel's face on each rank that owns one of its nodes,
  // from there to the other node, or to a cut where another rank owns that one (turned round
  // where it is its `from` node); its ghost there an empty cell of no face, holding the value
  // its owner sends.
  const bool halo = cut_ && lumped.halo();
  lumped_face_.assign(lumped.vessel_count(), -1);
  std::vector<std::int32_t> turned;
  for (std::size_t v = 0; v < net_.vessel_count(); ++v) {
    if (!solver_.is_lumped(v)) continue;
    const std::int32_t i = lumped.vessel_index(v);
    if (i < 0) continue;  // another rank's
    const auto face = static_cast<std::int32_t>(grid.face_count());
    lumped_face_[static_cast<std::size_t>(i)] = face;
    const std::int32_t a = lumped.from_node(i), b = lumped.to_node(i);
    if (halo) {
      const bool a_here = !lumped.ghost_node(a), b_here = !lumped.ghost_node(b);
      if (!a_here && !b_here)  // hold_at_an_own_node left it: its rank's only vessel
        throw SettingError("ranks", placeholder("ranks") + " " + std::to_string(solver_.rank_count()) +
                                        ": vessel " + std::to_string(net_.id[v]) + " is the only vessel of rank " +
                                        std::to_string(solver_.rank()) + ", which owns neither of its nodes, and " +
                                        "red cells and tracers are carried at the nodes' owners: run it on fewer ranks");
      grid.add_face(a_here ? a : b, a_here && b_here ? b : new_cut(), static_cast<std::int32_t>(v), mean_diameter(net_, v));
      if (!a_here) turned.push_back(face);
      end_faces[{static_cast<std::int32_t>(v), false}] = {face, a};
      end_faces[{static_cast<std::int32_t>(v), true}] = {face, b};
      continue;
    }
    const std::int32_t root = cut_ ? root_of[static_cast<std::size_t>(i)] : -1;
    if (root < 0) {
      grid.add_face(a, b, static_cast<std::int32_t>(v), mean_diameter(net_, v));
      continue;
    }
    const bool a_across = lumped.ghost_node(a);
    const std::int32_t here = a_across ? b : a, across = a_across ? a : b;
    grid.add_face(here, TransportGrid::boundary_side(boundaries.size() + static_cast<std::size_t>(root)),
                  static_cast<std::int32_t>(v), mean_diameter(net_, v));
    cut_->roots.face[static_cast<std::size_t>(root)] = face;
    cut_->roots.cell[static_cast<std::size_t>(root)] = here;
    cut_->roots.across[static_cast<std::size_t>(root)] = across;
    cut_->roots.ghost[static_cast<std::size_t>(across)] = root;
    if (a_across) turned.push_back(face);
  }
  for (std::size_t b = 0; b < boundaries.size(); ++b) {
    const std::int32_t k = lumped.empty() ? -1 : lumped.node_of(boundaries.node(b));
    if (k < 0 || lumped.ghost_node(k)) continue;  // another rank's
    if (node_boundary_faces_.second == 0) node_boundary_faces_.first = static_cast<std::int32_t>(grid.face_count());
    ++node_boundary_faces_.second;
    grid.add_face(k, TransportGrid::boundary_side(b), -1, 0.0);
  }
  // The 1D vessels' faces, vessel after vessel in the one-process grid's order. Spread over the
  // ranks, an end that meets another rank (its 0D node) goes to a cut, and an end of another
  // rank's vessel at a junction or 0D node here is a face from there to a cut: each cell's
  // faces in the one-process order.
  const bool spread = cut_ && cut_->spread;
  const int per_vessel = solver_.elements_per_vessel();
  for (const std::int32_t v : spread ? whole_one_d_order() : one_d_) {
    const double d0 = net_.diameter[static_cast<std::size_t>(v)], d1 = net_.diameter_at_to(static_cast<std::size_t>(v));
    const std::int32_t i = one_d_place(static_cast<std::size_t>(v));
    if (i < 0) {  // another rank's vessel (spread): its ends at a cell here
      for (const bool distal : {false, true}) {
        const auto found = end_side.find({v, distal});
        if (found == end_side.end() || found->second < 0) continue;
        const auto face = static_cast<std::int32_t>(grid.face_count());
        grid.add_face(found->second, new_cut(), v, distal ? d1 : d0);
        if (distal) turned.push_back(face);  // the one-process face runs into the cell
        end_faces[{v, distal}] = {face, found->second};
      }
      continue;
    }
    const std::int32_t first = vessel_first_cell_[static_cast<std::size_t>(i)], last = first + per_vessel * slices_ - 1;
    vessel_first_face_.push_back(static_cast<std::int32_t>(grid.face_count()));
    std::int32_t proximal = side_of(v, false), distal = side_of(v, true);
    if (proximal == remote_side) {
      proximal = new_cut();
      turned.push_back(static_cast<std::int32_t>(grid.face_count()));  // the one-process face runs from the node
    }
    if (distal == remote_side) distal = new_cut();
    if (spread) end_faces[{v, false}] = {static_cast<std::int32_t>(grid.face_count()), first};
    if (proximal >= 0) grid.add_face(proximal, first, v, d0);
    else grid.add_face(first, proximal, v, d0);
    proximal_sign_.push_back(proximal >= 0 ? 1 : -1);
    for (std::int32_t c = first; c < last; ++c) grid.add_face(c, c + 1, v, d0 + (d1 - d0) * (c + 1 - first) / (last - first + 1.0));
    if (spread) end_faces[{v, true}] = {static_cast<std::int32_t>(grid.face_count()), last};
    grid.add_face(last, distal, v, d1);
  }
  if (cut_) {
    cut_->face_sign.assign(grid.face_count(), 1);
    for (const std::int32_t f : turned) cut_->face_sign[static_cast<std::size_t>(f)] = -1;
  }
  return end_faces;
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
