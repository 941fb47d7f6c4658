#include "transport/red_cell_transport.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include "core/errors.hpp"
#include "physics/phase_separation.hpp"

namespace hemotree {

namespace {

// The Gauss-Seidel sweeps over cells on a directed cycle of the flow: each sweep is a
// contraction (every cell's update is a convex combination with a weight V / (V + Q_in) on
// what it held), so a few dozen reach round-off unless the cycle holds no volume at all.
constexpr int max_cycle_sweeps = 10000;
constexpr double cycle_tolerance = 1e-15;

}  // namespace

RedCellTransport::RedCellTransport(TransportGrid grid, std::vector<double> volume, double hematocrit,
                                   RedCellOptions options)
    : grid_(std::move(grid)), faces_(grid_), options_(options), volume_(std::move(volume)) {
  grid_.shrink_to_fit();
  const std::size_t cells = grid_.cell_count();
  if (volume_.size() != cells || grid_.fahraeus.size() != cells || grid_.b.size() != grid_.face_count() ||
      grid_.vessel.size() != grid_.face_count() || grid_.diameter.size() != grid_.face_count())
    throw InputError("red-cell transport: the grid's arrays and the " + std::to_string(volume_.size()) +
                     " cell volumes do not match its " + std::to_string(cells) + " cells");
  for (std::size_t c = 0; c < cells; ++c)
    if (!(volume_[c] >= 0) || !std::isfinite(volume_[c]))
      throw InputError("red-cell transport: cell " + std::to_string(c) + " has volume " + std::to_string(volume_[c]));
  if (!(hematocrit >= 0 && hematocrit < 1))
    throw InputError("red-cell transport: hematocrit " + std::to_string(hematocrit) + " is outside [0, 1)");
  discharge_.assign(cells, hematocrit);
  next_volume_.assign(cells, 0.0);
  share_.assign(grid_.face_count(), 1.0);
  last_outflow_.assign(grid_.boundaries, hematocrit);
  entered_.assign(grid_.boundaries, 0.0);
  left_.assign(grid_.boundaries, 0.0);
  // Where the law can apply: a node's cell with three faces, each in a vessel between cells
  // (a cut's face is one: the cell across it is another rank's).
  for (std::size_t c = 0; c < cells; ++c) {
    if (grid_.node[c] < 0 || faces_.start[c + 1] - faces_.start[c] != 3) continue;
    bool inner = true;
    for (auto i = faces_.start[c]; i < faces_.start[c + 1]; ++i) {
      const auto f = static_cast<std::size_t>(faces_.face[static_cast<std::size_t>(i)]);
      const std::int32_t b = grid_.b[f];
      inner = inner && (b >= 0 || grid_.is_cut(static_cast<std::size_t>(-1 - b))) && grid_.vessel[f] >= 0;
    }
    if (inner) candidates_.push_back(static_cast<std::int32_t>(c));
  }
  blood_face_.assign(grid_.face_count(), 0.0);
  cells_face_.assign(grid_.face_count(), 0.0);
  cells_before_.assign(cells, 0.0);
  // The flow order's arrays at their size from the start: what bytes() counts then is held.
  order_.cells.reserve(cells);
  order_.pending.reserve(cells);
  order_.direction.reserve(grid_.face_count());
}

void RedCellTransport::set_hematocrit(std::span<const double> discharge) {
  if (discharge.size() != discharge_.size())
    throw InputError("red-cell transport: " + std::to_string(discharge.size()) + " hematocrits for " +
                     std::to_string(discharge_.size()) + " cells");
  for (std::size_t c = 0; c < discharge.size(); ++c) {
    if (!(discharge[c] >= 0 && discharge[c] < 1))
      throw InputError("red-cell transport: hematocrit " + std::to_string(discharge[c]) + " of cell " +
                       std::to_string(c) + " is outside [0, 1)");
    discharge_[c] = discharge[c];
  }
}

void RedCellTransport::restore(std::span<const double> discharge, std::span<const double> volume,
                               std::span<const double> entered, std::span<const double> left, double adjusted,
                               std::span<const double> last_outflow) {
  discharge_.assign(discharge.begin(), discharge.end());
  volume_.assign(volume.begin(), volume.end());
  last_outflow_.assign(last_outflow.begin(), last_outflow.end());
  entered_.assign(entered.begin(), entered.end());
  left_.assign(left.begin(), left.end());
  adjusted_ = adjusted;
}

void RedCellTransport::set_volumes(std::span<const double> volume) {
  for (std::size_t c = 0; c < volume_.size(); ++c) {
    const double h = tube(c, discharge_[c]);
    adjusted_ += (volume[c] - volume_[c]) * h;
    volume_[c] = volume[c];
  }
}

double RedCellTransport::red_cells() const {
  double sum = 0;
  for (std::size_t c = 0; c < volume_.size(); ++c) sum += content(c);
  return sum;
}

double RedCellTransport::entered() const { return std::accumulate(entered_.begin(), entered_.end(), 0.0); }
double RedCellTransport::left() const { return std::accumulate(left_.begin(), left_.end(), 0.0); }

void RedCellTransport::split_at_nodes(std::span<const double> face_volume) {
  std::fill(share_.begin(), share_.end(), 1.0);
  separating_.clear();
  if (!options_.phase_separation) return;
  for (const std::int32_t cell : candidates_) {
    const auto c = static_cast<std::size_t>(cell);
    std::int32_t feed = -1, first = -1, second = -1;
    bool eligible = true;
    for (auto i = faces_.start[c]; i < faces_.start[c + 1] && eligible; ++i) {
      const std::int32_t f = faces_.face[static_cast<std::size_t>(i)];
      const auto fi = static_cast<std::size_t>(f);
      if (face_volume[fi] == 0) {
        eligible = false;
        break;
      }
      const bool out = (static_cast<std::size_t>(grid_.a[fi]) == c) == (face_volume[fi] > 0);
      if (!out) {
        if (feed >= 0) eligible = false;
        feed = f;
      } else if (first < 0) {
        first = f;
      } else {
        second = f;
      }
    }
    if (!eligible || feed < 0 || second < 0) continue;
    const auto fe = static_cast<std::size_t>(feed), f1 = static_cast<std::size_t>(first),
               f2 = static_cast<std::size_t>(second);
    Bifurcation bif;
    bif.feed_diameter = grid_.diameter[fe];
    bif.first_diameter = grid_.diameter[f1];
    bif.second_diameter = grid_.diameter[f2];
    const double q1 = std::abs(face_volume[f1]), q2 = std::abs(face_volume[f2]);
    bif.flow_fraction = q1 / (q1 + q2);
    bif.feed_hematocrit = discharge_[c];
    bif.diameter_scale = options_.diameter_scale;
    // The law has no split where X0 >= 1/2 (a feed under 1.93 (1 - H) um): mixed there.
    if (!law_splits(bif)) continue;
    const double fqe = red_cell_fraction(bif);
    // Each daughter's hematocrit over the feed's: its share of the cells over its share of the
    // flow, the latter from the flows themselves: a daughter of round-off flow (a closed end:
    // 1e-27 against 1e-7) has 1 - flow_fraction = 0 exactly, and 0 / 0 put NaN in the run.
    share_[f1] = fqe * (q1 + q2) / q1;
    share_[f2] = (1 - fqe) * (q1 + q2) / q2;
    separating_.push_back(cell);
  }
}

double RedCellTransport::face_hematocrit(std::size_t f, std::span<const double> face_volume,
                                         std::span<const double> inflow_hematocrit) const {
  if (face_volume[f] > 0) return share_[f] * discharge_[static_cast<std::size_t>(grid_.a[f])];
  const std::int32_t b = grid_.b[f];
  if (b >= 0) return share_[f] * discharge_[static_cast<std::size_t>(b)];
  const auto boundary = static_cast<std::size_t>(-1 - b);
  const double given = inflow_hematocrit[boundary];
  return std::isnan(given) ? last_outflow_[boundary] : given;
}

double RedCellTransport::solve_cell(std::size_t c, std::span<const double> face_volume,
                                    std::span<const double> inflow_hematocrit) {
  double rhs = cells_before_[c], out = 0;
  for (auto i = faces_.start[c]; i < faces_.start[c + 1]; ++i) {
    const auto f = static_cast<std::size_t>(faces_.face[static_cast<std::size_t>(i)]);
    const double q = face_volume[f];
    if (q == 0) continue;
    if ((static_cast<std::size_t>(grid_.a[f]) == c) == (q > 0)) out += std::abs(q);
    else rhs += std::abs(q) * face_hematocrit(f, face_volume, inflow_hematocrit);
  }
  // W H_T(H) + out H = rhs with H_T = H (k + (1 - k) H): a H^2 + b H = rhs, the root that
  // vanishes with rhs (written to keep its digits whatever the sign of a). W is taken as it
  // is, even the round-off below zero that a junction's volume can hold (its flows balance
  // to the Newton tolerance): what the content is then counted with.
  const double w = next_volume_[c], k = grid_.fahraeus[c];
  const double a = (1 - k) * w, b = k * w + out;
  if (!(b > 0)) return discharge_[c];  // nothing here and nothing through: it keeps its value
  const double disc = std::max(b * b + 4 * a * rhs, 0.0);
  return 2 * rhs / (b + std::sqrt(disc));
}

void RedCellTransport::step(std::span<const double> face_volume, std::span<const double> inflow_hematocrit) {
  begin_step(face_volume);
  solve(face_volume, inflow_hematocrit, Cells::all);
  end_step(face_volume, inflow_hematocrit);
}

void RedCellTransport::begin_step(std::span<const double> face_volume) {
  const std::size_t cells = grid_.cell_count(), faces = grid_.face_count();
  if (face_volume.size() != faces)
    throw InputError("red-cell transport: a step needs " + std::to_string(faces) + " face volumes and " +
                     std::to_string(grid_.boundaries) + " boundary hematocrits");
  // The blood: each cell's volume after the step from what its faces passed.
  next_volume_ = volume_;
  for (std::size_t f = 0; f < faces; ++f) {
    next_volume_[static_cast<std::size_t>(grid_.a[f])] -= face_volume[f];
    if (grid_.b[f] >= 0) next_volume_[static_cast<std::size_t>(grid_.b[f])] += face_volume[f];
  }
  for (std::size_t c = 0; c < cells; ++c) cells_before_[c] = volume_[c] * tube(c, discharge_[c]);
  split_at_nodes(face_volume);
  order_.update(grid_, faces_, face_volume);
  if (grid_.cuts == 0) return;
  // Which cells a cut's inflow reaches: in flow order, from the cuts and the cells it reached.
  after_cut_.assign(cells, 0);
  for (const std::int32_t cell : order_.cells) {
    const auto c = static_cast<std::size_t>(cell);
    for (auto i = faces_.start[c]; i < faces_.start[c + 1] && !after_cut_[c]; ++i) {
      const auto f = static_cast<std::size_t>(faces_.face[static_cast<std::size_t>(i)]);
      const double q = face_volume[f];
      if (q == 0 || (static_cast<std::size_t>(grid_.a[f]) == c) == (q > 0)) continue;  // none in through f
      const std::int32_t from = static_cast<std::size_t>(grid_.a[f]) == c ? grid_.b[f] : grid_.a[f];
      after_cut_[c] = from >= 0 ? after_cut_[static_cast<std::size_t>(from)]
                                : static_cast<unsigned char>(grid_.is_cut(static_cast<std::size_t>(-1 - from)));
    }
  }
}

void RedCellTransport::solve(std::span<const double> face_volume, std::span<const double> inflow_hematocrit, Cells which) {
  const std::size_t cells = grid_.cell_count();
  if (inflow_hematocrit.size() != grid_.boundaries)
    throw InputError("red-cell transport: a step needs " + std::to_string(grid_.face_count()) + " face volumes and " +
                     std::to_string(grid_.boundaries) + " boundary hematocrits");
  const std::size_t ordered = cells - order_.cyclic;
  for (std::size_t k = 0; k < ordered; ++k) {
    const auto c = static_cast<std::size_t>(order_.cells[k]);
    if (solves(c, which)) discharge_[c] = solve_cell(c, face_volume, inflow_hematocrit);
  }
  if (order_.cyclic > 0 && which != Cells::before_cuts) {
    double change = std::numeric_limits<double>::infinity();
    int sweep = 0;
    for (; sweep < max_cycle_sweeps && change > cycle_tolerance; ++sweep) {
      change = 0;
      for (std::size_t k = ordered; k < cells; ++k) {
        const auto c = static_cast<std::size_t>(order_.cells[k]);
        const double next = solve_cell(c, face_volume, inflow_hematocrit);
        change = std::max(change, std::abs(next - discharge_[c]));
        discharge_[c] = next;
      }
    }
    if (change > cycle_tolerance)
      throw InputError("red-cell transport: the hematocrit on a circulation of the flow through network node " +
                       std::to_string(grid_.node[static_cast<std::size_t>(order_.cells[ordered])]) +
                       " did not settle in " + std::to_string(max_cycle_sweeps) + " sweeps");
  }
}

void RedCellTransport::end_step(std::span<const double> face_volume, std::span<const double> inflow_hematocrit) {
  const std::size_t faces = grid_.face_count();
  // What moved: red cells per face at the new upwind values, and the boundaries' balance.
  for (std::size_t f = 0; f < faces; ++f) {
    const double q = face_volume[f];
    const double cells_through = q == 0 ? 0.0 : q * face_hematocrit(f, face_volume, inflow_hematocrit);
    cells_face_[f] = cells_through;
    blood_face_[f] = q;
    if (grid_.b[f] >= 0 || q == 0) continue;
    const auto boundary = static_cast<std::size_t>(-1 - grid_.b[f]);
    if (grid_.is_cut(boundary)) continue;  // the other side's cells, not the network's
    if (q > 0) {
      left_[boundary] += cells_through;
      last_outflow_[boundary] = cells_through / q;
    } else {
      entered_[boundary] -= cells_through;
    }
  }
  volume_.swap(next_volume_);  // blood_before() and blood_after() read the two
}

}  // namespace hemotree
