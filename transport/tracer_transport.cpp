#include "transport/tracer_transport.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

#include "core/errors.hpp"

namespace hemotree {

namespace {
constexpr int max_cycle_sweeps = 10000;
constexpr double cycle_tolerance = 1e-15;
}  // namespace

TracerTransport::TracerTransport(std::size_t cells, std::size_t boundaries, TracerCarrier carrier)
    : carrier_(carrier), concentration_(cells, 0.0), last_outflow_(boundaries, 0.0), entered_(boundaries, 0.0),
      left_(boundaries, 0.0) {}

double TracerTransport::carried(const RedCellTransport& red_cells, std::size_t c) const {
  switch (carrier_) {
    case TracerCarrier::plasma:
      return red_cells.volume()[c] - red_cells.content(c);
    case TracerCarrier::cells:
      return red_cells.content(c);
    case TracerCarrier::blood:
      break;
  }
  return red_cells.volume()[c];
}

double TracerTransport::amount(const RedCellTransport& red_cells) const {
  double sum = 0;
  for (std::size_t c = 0; c < concentration_.size(); ++c) sum += carried(red_cells, c) * concentration_[c];
  return sum;
}

double TracerTransport::entered() const { return std::accumulate(entered_.begin(), entered_.end(), 0.0); }
double TracerTransport::left() const { return std::accumulate(left_.begin(), left_.end(), 0.0); }

// The concentration of the carrier entering through face f into its downstream cell.
double TracerTransport::inflowing(std::size_t f, const RedCellTransport& red_cells, std::span<const double> inflow,
                                  Injection injected) const {
  const TransportGrid& grid = red_cells.grid();
  const double q = red_cells.blood_through()[f];
  double c;
  if (q > 0) {
    c = concentration_[static_cast<std::size_t>(grid.a[f])];
  } else if (grid.b[f] >= 0) {
    c = concentration_[static_cast<std::size_t>(grid.b[f])];
  } else {
    const auto boundary = static_cast<std::size_t>(-1 - grid.b[f]);
    c = std::isnan(inflow[boundary]) ? last_outflow_[boundary] : inflow[boundary];
  }
  return f == injected.face ? c + injected.concentration : c;
}

double TracerTransport::solve_cell(std::size_t c, double start, const RedCellTransport& red_cells, const CarrierStep& m,
                                   std::span<const double> inflow, Injection injected) const {
  const TransportGrid& grid = red_cells.grid();
  const CellFaces& faces = red_cells.faces();
  const std::span<const double> blood = red_cells.blood_through();
  double rhs = m.before(c) * start, carrier = m.after(c);
  for (auto i = faces.start[c]; i < faces.start[c + 1]; ++i) {
    const auto f = static_cast<std::size_t>(faces.face[static_cast<std::size_t>(i)]);
    if (blood[f] == 0) continue;
    const double through = std::abs(m.face(f));
    if ((static_cast<std::size_t>(grid.a[f]) == c) == (blood[f] > 0)) carrier += through;
    else rhs += through * inflowing(f, red_cells, inflow, injected);
  }
  return carrier > 0 ? rhs / carrier : start;  // no carrier here or through: unchanged
}

double TracerTransport::step_start(std::size_t c, std::size_t k, std::size_t ordered) const {
  if (start_per_cell_) return start_[c];
  return k < ordered ? concentration_[c] : start_[k - ordered];
}

void TracerTransport::step(const RedCellTransport& red_cells, std::span<const double> inflow,
                           Injection injected) {
  begin_step(red_cells, inflow, injected);
  solve(red_cells, inflow, injected, RedCellTransport::Cells::all);
  end_step(red_cells, inflow, injected);
}

void TracerTransport::begin_step(const RedCellTransport& red_cells, std::span<const double> inflow,
                                 Injection injected) {
  const TransportGrid& grid = red_cells.grid();
  if (inflow.size() != grid.boundaries || (injected.face != Injection::none && injected.face >= grid.face_count()))
    throw InputError("tracer transport: a step needs " + std::to_string(grid.boundaries) +
                     " boundary concentrations, and an injection at one of its " + std::to_string(grid.face_count()) +
                     " faces or none");
  // The step starts from these, however often a cell is solved: the cells on a circulation
  // (its sweeps) and, on a grid with cuts, every cell (the rounds of a run over ranks). A cell
  // solved once reads its own value, not yet moved (8 B a cell less).
  const FlowOrder& order = red_cells.order();
  start_per_cell_ = grid.cuts > 0;
  if (start_per_cell_) {
    start_.assign(concentration_.begin(), concentration_.end());
  } else {
    start_.resize(order.cyclic);
    const std::size_t ordered = concentration_.size() - order.cyclic;
    for (std::size_t k = 0; k < order.cyclic; ++k) start_[k] = concentration_[static_cast<std::size_t>(order.cells[ordered + k])];
  }
  // What the injections add, at the concentrations upstream before they move.
  const CarrierStep m = carrier_step(red_cells);
  if (injected.face != Injection::none) injected_ += std::abs(m.face(injected.face)) * injected.concentration;
}

void TracerTransport::solve(const RedCellTransport& red_cells, std::span<const double> inflow,
                            Injection injected, RedCellTransport::Cells which) {
  const FlowOrder& order = red_cells.order();
  const CarrierStep m = carrier_step(red_cells);
  const std::size_t cells = concentration_.size(), ordered = cells - order.cyclic;
  for (std::size_t k = 0; k < ordered; ++k) {
    const auto c = static_cast<std::size_t>(order.cells[k]);
    if (red_cells.solves(c, which)) concentration_[c] = solve_cell(c, step_start(c, k, ordered), red_cells, m, inflow, injected);
  }
  if (order.cyclic > 0 && which != RedCellTransport::Cells::before_cuts) {
    double change = std::numeric_limits<double>::infinity();
    for (int sweep = 0; sweep < max_cycle_sweeps && change > cycle_tolerance; ++sweep) {
      change = 0;
      for (std::size_t k = ordered; k < cells; ++k) {
        const auto c = static_cast<std::size_t>(order.cells[k]);
        const double next = solve_cell(c, step_start(c, k, ordered), red_cells, m, inflow, injected);
        change = std::max(change, std::abs(next - concentration_[c]) / std::max(std::abs(next), 1.0));
        concentration_[c] = next;
      }
    }
  }
}

void TracerTransport::end_step(const RedCellTransport& red_cells, std::span<const double> inflow,
                               Injection injected) {
  const TransportGrid& grid = red_cells.grid();
  const CarrierStep m = carrier_step(red_cells);
  const std::span<const double> blood = red_cells.blood_through();
  for (std::size_t f = 0; f < grid.face_count(); ++f) {
    if (blood[f] == 0 || grid.b[f] >= 0) continue;
    const double c = inflowing(f, red_cells, inflow, injected);
    const auto boundary = static_cast<std::size_t>(-1 - grid.b[f]);
    if (grid.is_cut(boundary)) continue;  // the other side's cells, not the network's
    if (blood[f] > 0) {
      left_[boundary] += std::abs(m.face(f)) * c;
      last_outflow_[boundary] = c;
    } else {
      entered_[boundary] += std::abs(m.face(f)) * (f == injected.face ? c - injected.concentration : c);  // an injection there is counted apart
    }
  }
}

void TracerTransport::restore(std::span<const double> concentration, std::span<const double> last_outflow,
                              std::span<const double> entered, std::span<const double> left, double injected,
                              double adjusted) {
  concentration_.assign(concentration.begin(), concentration.end());
  last_outflow_.assign(last_outflow.begin(), last_outflow.end());
  entered_.assign(entered.begin(), entered.end());
  left_.assign(left.begin(), left.end());
  injected_ = injected;
  adjusted_ = adjusted;
}

}  // namespace hemotree
