// The transport grid of a PulseSolver's network (solver/flow_transport.hpp): a cell for every
// node of 0D vessels, slices of every 1D element, a cell for every junction of 1D vessels;
// a face for every 0D vessel, every boundary at a 0D node and the ends and slice boundaries
// of every 1D vessel, each vessel's faces one after another. Over ranks a cut where a root
// vessel or a spread vessel's end crosses to another rank.
#include "solver/flow_transport.hpp"

#include <algorithm>
#include <limits>
#include <map>
#include <numbers>
#include <string>
#include <utility>

#include "core/errors.hpp"
#include "core/setting_error.hpp"
#include "physics/phase_separation.hpp"
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

}  // namespace

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
    const double d = net_.mean_diameter(v), half = 0.125 * std::numbers::pi * d * d * net_.length[v];
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
      grid.add_face(a_here ? a : b, a_here && b_here ? b : new_cut(), static_cast<std::int32_t>(v), net_.mean_diameter(v));
      if (!a_here) turned.push_back(face);
      end_faces[{static_cast<std::int32_t>(v), false}] = {face, a};
      end_faces[{static_cast<std::int32_t>(v), true}] = {face, b};
      continue;
    }
    const std::int32_t root = cut_ ? root_of[static_cast<std::size_t>(i)] : -1;
    if (root < 0) {
      grid.add_face(a, b, static_cast<std::int32_t>(v), net_.mean_diameter(v));
      continue;
    }
    const bool a_across = lumped.ghost_node(a);
    const std::int32_t here = a_across ? b : a, across = a_across ? a : b;
    grid.add_face(here, TransportGrid::boundary_side(boundaries.size() + static_cast<std::size_t>(root)),
                  static_cast<std::int32_t>(v), net_.mean_diameter(v));
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

}  // namespace hemotree
