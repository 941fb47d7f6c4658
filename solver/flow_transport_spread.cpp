// Red cells and tracers where the 1D vessels are spread over the ranks (docs/transport.md,
// "Over MPI ranks"; the flow's cut: pulse/one_d_cut.hpp).
//
// Each rank carries the slices of its own 1D vessels, the nodes of its 0D vessels and every
// junction where one of its vessels ends (the flow solves such a junction on each of its
// ranks alike; so does the transport, each copy numbered by the rank of its first end). An end
// across the cut is a *link*: on the rank holding the cell it meets (a junction, a 0D node), a
// face from that cell to a cut; where the end's vessel meets another rank's 0D node, its own
// end face goes to a cut as well, and the node's rank answers. Each cut takes its inflow from
// the rank of the cell across it: s_f H_D of that cell (the red cells), or what crosses the
// face (each tracer), the product taken as the one-process run takes it; and, once a step, its
// volume from the vessel's rank.
//
// Where the 0D system is spread too (a halo: pulse/lumped_halo.hpp), each node's cell is its
// owner's, with every face at it; a 0D vessel whose nodes two ranks own has a face on both, to
// a cut on each, and each node's owner sends the other its s_f H_D and H_D (the other's ghost
// cell takes H_D, for probes). Both compute the face's volume from the same flow: none crosses.
//
// The implicit upwind step needs every cell's upwind cells first, and along the 1D vessels the
// flow crosses the cut as often as the vessels change rank: so a step is solved in rounds. Each
// round solves every cell of the rank with the cuts' inflows of the round before (the first:
// the last step's), then sends each link's numbers. On a tree, and wherever the flow of the
// step has no circulation, a cell's value is a function of its upwind cells alone (after the
// first round only the cells a cut's inflow reaches are solved again): once a round changes
// no inflow on any rank, every cell holds the one-process value, bit for bit,
// after at most one round more than the cut crossings along any path of the flow. A circulation
// across the cut (a loop of 1D vessels) settles as the one-process run's Gauss-Seidel does, to
// 1e-15, after that many rounds.
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "core/errors.hpp"
#include "mpi/session.hpp"
#include "solver/flow_transport.hpp"

namespace hemotree {

namespace {
constexpr std::size_t max_rounds = 10000;
constexpr double circulation_tolerance = 1e-15;  // the one-process run's, for the cells on a circulation
constexpr int tag = 22;
}  // namespace

std::vector<std::int32_t> FlowTransport::whole_one_d_order() const {
  // The one-process run's 1D vessels are in the order of their elements.
  std::vector<std::pair<std::int32_t, std::int32_t>> by_element;
  for (std::size_t v = 0; v < net_.vessel_count(); ++v)
    if (!solver_.is_lumped(v)) by_element.emplace_back(solver_.first_element(v), static_cast<std::int32_t>(v));
  std::sort(by_element.begin(), by_element.end());
  std::vector<std::int32_t> order;
  order.reserve(by_element.size());
  for (const auto& [element, v] : by_element) order.push_back(v);
  return order;
}

void FlowTransport::place_spread_cut(const EndFaces& end_faces) {
  Cut& cut = *cut_;
  const TransportGrid& grid = red_cells_->grid();
  const LumpedVessels& lumped = solver_.lumped();
  const NetworkBoundaries& ends = solver_.network_boundaries();
  const std::size_t n = net_.vessel_count();
  const std::span<const std::int32_t> rank = solver_.vessel_ranks();
  const int me = solver_.rank();

  // The one-process grid: the 0D part (zero_d_places), every 1D vessel's slices, the
  // junctions; its 1D faces after the 0D part's, every 1D vessel's.
  const ZeroDPlaces whole = zero_d_places();
  const std::vector<bool>& zero_d = whole.zero_d;
  const std::vector<std::int32_t> one_d = whole_one_d_order();
  std::vector<std::int32_t> one_d_whole(n, -1);
  for (std::size_t w = 0; w < one_d.size(); ++w) one_d_whole[static_cast<std::size_t>(one_d[w])] = static_cast<std::int32_t>(w);
  const auto per_vessel = static_cast<std::int32_t>(solver_.elements_per_vessel() * slices_);
  const std::size_t junctions = ends.junction_offset.empty() ? 0 : ends.junction_offset.size() - 1;
  std::map<std::int64_t, std::int32_t> junction_at;  // network node -> junction
  std::map<std::pair<std::int32_t, bool>, std::int32_t> junction_of;  // end -> junction
  for (std::size_t j = 0; j < junctions; ++j)
    for (auto e = ends.junction_offset[j]; e < ends.junction_offset[j + 1]; ++e) {
      const VesselEnd& end = ends.junction_ends[static_cast<std::size_t>(e)];
      const auto v = static_cast<std::size_t>(end.vessel);
      junction_at[end.distal ? net_.to[v] : net_.from[v]] = static_cast<std::int32_t>(j);
      junction_of[{end.vessel, end.distal}] = static_cast<std::int32_t>(j);
    }

  const auto slices_start = static_cast<std::int32_t>(whole.nodes);
  const std::int32_t junctions_start = slices_start + static_cast<std::int32_t>(one_d.size()) * per_vessel;
  const std::size_t here_nodes = lumped.empty() ? 0 : lumped.network_node_count();
  cut.cell_place.assign(grid.cell_count(), -1);
  for (std::size_t c = 0; c < here_nodes; ++c) {
    cut.cell_place[c] = whole.node_place[static_cast<std::size_t>(grid.node[c])];
    if (lumped.halo() && lumped.ghost_node(static_cast<std::int32_t>(c))) cut.copies.push_back(static_cast<std::int32_t>(c));
  }
  for (std::size_t i = 0; i < one_d_.size(); ++i)
    for (std::int32_t s = 0; s < per_vessel; ++s)
      cut.cell_place[static_cast<std::size_t>(vessel_first_cell_[i] + s)] =
          slices_start + one_d_whole[static_cast<std::size_t>(one_d_[i])] * per_vessel + s;
  for (std::size_t c = here_nodes; c < grid.cell_count(); ++c)
    if (grid.node[c] >= 0) cut.cell_place[c] = junctions_start + junction_at.at(grid.node[c]);
  cut.cells = static_cast<std::size_t>(junctions_start) + junctions;

  auto one_d_face = [&](std::int32_t v, std::int32_t k) {  // face k of vessel v, 0 its proximal
    return whole.one_d_faces + one_d_whole[static_cast<std::size_t>(v)] * (per_vessel + 1) + k;
  };
  cut.face_place.assign(grid.face_count(), -1);
  for (std::size_t f = 0; f < grid.face_count(); ++f) cut.face_place[f] = whole.face_place(grid, f);
  for (std::size_t i = 0; i < one_d_.size(); ++i)
    for (std::int32_t k = 0; k <= per_vessel; ++k)
      cut.face_place[static_cast<std::size_t>(vessel_first_face_[i] + k)] = one_d_face(one_d_[i], k);
  for (const auto& [end, face] : end_faces)  // another rank's 1D vessel's end
    if (!zero_d[static_cast<std::size_t>(end.first)] && one_d_place(static_cast<std::size_t>(end.first)) < 0)
      cut.face_place[static_cast<std::size_t>(face.first)] = one_d_face(end.first, end.second ? per_vessel : 0);
  cut.faces = static_cast<std::size_t>(whole.one_d_faces) + one_d.size() * static_cast<std::size_t>(per_vessel + 1);

  // The links, in the run's order of vessel ends (every rank alike): a 1D end at a junction,
  // to every other rank with an end there; at another rank's 0D node, both ways; then, the 0D
  // system spread, each 0D vessel whose nodes two ranks own, each node's owner to the other.
  const std::span<const std::int32_t> node_rank = solver_.lumped_node_ranks();
  std::map<std::pair<std::int32_t, bool>, std::int64_t> coupled_node;
  for (const auto& c : ends.coupled) coupled_node[{c.end.vessel, c.end.distal}] = c.node;
  std::map<int, Cut::Links::Neighbour> by_rank;
  auto link = [&](int receiver, int supplier, std::pair<std::int32_t, bool> end, bool volume, bool held = false) {
    ++cut.spread->count;
    if (receiver == me) {
      Cut::Links::Neighbour& from = by_rank[supplier];
      from.receive_face.push_back(end_faces.at(end).first);
      from.receive_volume.push_back(volume);
      from.receive_cell.push_back(held ? end_faces.at(end).second : -1);
    }
    if (supplier == me) {
      Cut::Links::Neighbour& to = by_rank[receiver];
      to.send_face.push_back(end_faces.at(end).first);
      to.send_cell.push_back(end_faces.at(end).second);
      to.send_volume.push_back(volume);
    }
  };
  for (const std::int32_t v : one_d) {
    const int rv = rank[static_cast<std::size_t>(v)];
    for (const bool distal : {false, true}) {
      const std::pair<std::int32_t, bool> end{v, distal};
      if (const auto j = junction_of.find(end); j != junction_of.end()) {
        std::set<int> holders;
        const auto J = static_cast<std::size_t>(j->second);
        for (auto e = ends.junction_offset[J]; e < ends.junction_offset[J + 1]; ++e)
          holders.insert(rank[static_cast<std::size_t>(ends.junction_ends[static_cast<std::size_t>(e)].vessel)]);
        for (const int r : holders)
          if (r != rv) link(r, rv, end, true);
      } else if (const auto c = coupled_node.find(end); c != coupled_node.end()) {
        const int rn = node_rank[static_cast<std::size_t>(c->second)];
        if (rn == rv) continue;
        link(rn, rv, end, true);
        link(rv, rn, end, false);
      }
    }
  }
  if (lumped.halo())
    for (std::size_t v = 0; v < n; ++v) {
      if (!zero_d[v]) continue;
      const int ra = node_rank[static_cast<std::size_t>(net_.from[v])], rb = node_rank[static_cast<std::size_t>(net_.to[v])];
      if (ra == rb) continue;
      link(rb, ra, {static_cast<std::int32_t>(v), false}, false, true);
      link(ra, rb, {static_cast<std::int32_t>(v), true}, false, true);
    }
  for (auto& [r, neighbour] : by_rank) {
    neighbour.rank = r;
    cut.spread->neighbours.push_back(std::move(neighbour));
  }
}

void FlowTransport::exchange_numbers(const std::vector<std::vector<double>>& out, std::vector<std::vector<double>>& in) {
  Cut& cut = *cut_;
  std::vector<int> ranks;
  for (const Cut::Links::Neighbour& nb : cut.spread->neighbours) ranks.push_back(nb.rank);
  exchange_with_neighbours(ranks, out, in, tag, cut.spread->traffic);
}

void FlowTransport::take_cut_volumes() {
  // Each link's volume, as the one-process face has it, from the vessel's rank.
  Cut& cut = *cut_;
  const std::size_t count = cut.spread->neighbours.size();
  std::vector<std::vector<double>> out(count), in(count);
  for (std::size_t i = 0; i < count; ++i) {
    const Cut::Links::Neighbour& nb = cut.spread->neighbours[i];
    for (std::size_t k = 0; k < nb.send_face.size(); ++k)
      if (nb.send_volume[k]) {
        const auto f = static_cast<std::size_t>(nb.send_face[k]);
        out[i].push_back(cut.face_sign[f] * face_volume_[f]);
      }
    in[i].resize(static_cast<std::size_t>(std::count(nb.receive_volume.begin(), nb.receive_volume.end(), 1)));
  }
  exchange_numbers(out, in);
  for (std::size_t i = 0; i < count; ++i) {
    const Cut::Links::Neighbour& nb = cut.spread->neighbours[i];
    std::size_t j = 0;
    for (std::size_t k = 0; k < nb.receive_face.size(); ++k)
      if (nb.receive_volume[k]) {
        const auto f = static_cast<std::size_t>(nb.receive_face[k]);
        face_volume_[f] = cut.face_sign[f] * in[i][j++];
      }
  }
}

void FlowTransport::spread_rounds(std::size_t per_link, const char* what,
                                  const std::function<void(RedCellTransport::Cells)>& solve,
                                  const std::function<void(std::size_t, std::size_t, double*)>& here,
                                  const std::function<double(std::size_t, std::int32_t, const double*)>& across) {
  Cut& cut = *cut_;
  const std::size_t count = cut.spread->neighbours.size();
  // Past one round more than the links (what any path of the flow crosses, at most), only a
  // circulation across the cut is still moving.
  const std::size_t exact = cut.spread->count + 1;
  using Cells = RedCellTransport::Cells;
  for (std::size_t round = 1;; ++round) {
    // After the first round only the cells a cut's inflow reaches can change.
    on_every_rank([&] { solve(round == 1 ? Cells::all : Cells::after_cuts); });  // a failure, every rank's
    std::vector<std::vector<double>> out(count), in(count);
    for (std::size_t i = 0; i < count; ++i) {
      const Cut::Links::Neighbour& nb = cut.spread->neighbours[i];
      out[i].resize(per_link * nb.send_face.size());
      for (std::size_t k = 0; k < nb.send_face.size(); ++k)
        here(static_cast<std::size_t>(nb.send_face[k]), static_cast<std::size_t>(nb.send_cell[k]), &out[i][per_link * k]);
      in[i].resize(per_link * nb.receive_face.size());
    }
    exchange_numbers(out, in);
    double change = 0;
    for (std::size_t i = 0; i < count; ++i) {
      const Cut::Links::Neighbour& nb = cut.spread->neighbours[i];
      for (std::size_t k = 0; k < nb.receive_face.size(); ++k)
        change = std::max(change, across(static_cast<std::size_t>(nb.receive_face[k]), nb.receive_cell[k], &in[i][per_link * k]));
    }
    const double started = MPI_Wtime();
    MPI_Allreduce(MPI_IN_PLACE, &change, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    cut.spread->traffic.seconds += MPI_Wtime() - started;
    ++cut.spread->traffic.rounds;
    if (change == 0) return;
    if (round > exact && change <= circulation_tolerance) {
      on_every_rank([&] { solve(Cells::after_cuts); });  // with the inflows settled
      return;
    }
    if (round >= max_rounds)
      throw Collective<InputError>(std::string(what) + ": the inflows across the ranks' cut did not settle in " +
                                   std::to_string(max_rounds) + " rounds (a circulation of the flow through it)");
  }
}

void FlowTransport::advance_spread() {
  take_cut_volumes();
  RedCellTransport& cells = *red_cells_;
  const TransportGrid& grid = cells.grid();
  cells.begin_step(face_volume_);
  // A link's numbers: what enters through it (s_f H_D of the cell it leaves), and that cell's
  // H_D (a ghost node's, for the probes there).
  auto moved = [](double& held, double sent) {
    const double change = held == sent ? 0.0 : std::abs(sent - held);
    held = sent;
    return change;
  };
  spread_rounds(
      2, "the red cells' step", [&](RedCellTransport::Cells which) { cells.solve(face_volume_, inflow_hematocrit_, which); },
      [&](std::size_t face, std::size_t cell, double* numbers) {
        numbers[0] = cells.separation_share(face) * cells.discharge_hematocrit()[cell];
        numbers[1] = cells.discharge_hematocrit()[cell];
      },
      [&](std::size_t face, std::int32_t held, const double* numbers) {
        double change = moved(inflow_hematocrit_[static_cast<std::size_t>(-1 - grid.b[face])], numbers[0]);
        if (held >= 0) {
          double h = cells.discharge_hematocrit()[static_cast<std::size_t>(held)];
          change = std::max(change, moved(h, numbers[1]));
          cells.hold(static_cast<std::size_t>(held), h);
        }
        return change;
      });
  cells.end_step(face_volume_, inflow_hematocrit_);
  ++advances_;
  ++cut_->spread->traffic.steps;
  mark();
  if (!tracers_.empty()) step_tracers_spread(last_time_, solver_.time());
  last_time_ = solver_.time();
}

void FlowTransport::step_tracers_spread(double t0, double t1) {
  // Every tracer rides on the red cells' whole step, in rounds of its own (each link, every
  // tracer's concentration crossing it), each starting from the cuts' inflows of its last step.
  Cut& cut = *cut_;
  const TransportGrid& grid = red_cells_->grid();
  const std::size_t count = tracers_.size(), cuts = grid.cuts, first_cut = grid.boundaries - cuts;
  if (cut.spread->tracer_in.size() != count * cuts) cut.spread->tracer_in.assign(count * cuts, 0.0);
  for (std::size_t k = 0; k < count; ++k) {
    tracer_given(k, t0, t1);
    for (std::size_t j = 0; j < cuts; ++j) tracer_inflow_[k][first_cut + j] = cut.spread->tracer_in[k * cuts + j];
    tracers_[k].begin_step(*red_cells_, tracer_inflow_[k], tracer_injected_[k]);
  }
  // A link's numbers: each tracer's concentration entering through it, then each one's in the
  // cell it leaves (a ghost node's, for the probes there).
  spread_rounds(
      2 * count, "the tracers' step",
      [&](RedCellTransport::Cells which) {
        for (std::size_t k = 0; k < count; ++k) tracers_[k].solve(*red_cells_, tracer_inflow_[k], tracer_injected_[k], which);
      },
      [&](std::size_t face, std::size_t cell, double* numbers) {
        for (std::size_t k = 0; k < count; ++k) {
          numbers[k] = tracers_[k].inflowing(face, *red_cells_, tracer_inflow_[k], tracer_injected_[k]);
          numbers[count + k] = tracers_[k].concentration()[cell];
        }
      },
      [&](std::size_t face, std::int32_t held, const double* numbers) {
        const auto b = static_cast<std::size_t>(-1 - grid.b[face]);
        auto moved = [](double& value, double sent) {
          const double change = value == sent ? 0.0 : std::abs(sent - value) / std::max(std::abs(sent), 1.0);
          value = sent;
          return change;
        };
        double change = 0;
        for (std::size_t k = 0; k < count; ++k) {
          change = std::max(change, moved(tracer_inflow_[k][b], numbers[k]));
          cut.spread->tracer_in[k * cuts + (b - first_cut)] = numbers[k];
          if (held < 0) continue;
          double c = tracers_[k].concentration()[static_cast<std::size_t>(held)];
          change = std::max(change, moved(c, numbers[count + k]));
          tracers_[k].hold(static_cast<std::size_t>(held), c);
        }
        return change;
      });
  for (std::size_t k = 0; k < count; ++k) {
    tracers_[k].end_step(*red_cells_, tracer_inflow_[k], tracer_injected_[k]);
    follow_curve(k, t0, t1);
  }
}

}  // namespace hemotree
