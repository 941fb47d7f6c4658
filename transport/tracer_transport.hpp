// An indicator carried by plasma, by the red cells or by whole blood: its concentration per
// volume of its carrier in every cell of the red-cell transport's grid, moved by the same
// implicit upwind step on the carrier's own volumes (docs/transport.md, "Tracers").
//
// Each cell, in the red-cell step's flow order:
//   C+ (M+ + m_out) = M C + sum_in m_f C_f
// with M, M+ the carrier in the cell before and after the step and m the carrier through
// each face (CarrierStep). The carrier's own balance closes per cell (M+ + m_out = M + m_in),
// so C+ is a convex combination of C and the inflows: 0 <= C, no new extrema, and the
// tracer in the network changes by what the boundaries let in and out plus what is injected.
// On a grid with cuts (a run over ranks) a step runs in the red cells' parts, on their split.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/array_bytes.hpp"
#include "transport/red_cell_transport.hpp"

namespace hemotree {

// A concentration added to the carrier crossing one face in a step (a tracer given inside
// the network, at a vessel), or none.
struct Injection {
  static constexpr std::size_t none = static_cast<std::size_t>(-1);
  std::size_t face = none;
  double concentration = 0;
};

class TracerTransport {
 public:
  TracerTransport(std::size_t cells, std::size_t boundaries, TracerCarrier carrier);

  // Advances the tracer over the red-cell transport's last step (call right after it).
  // inflow: per boundary, the concentration of the carrier it lets in (NaN: what last left
  // there). injected: a concentration added to the carrier crossing one face in this step
  // (or none), the injection's amount counted in injected().
  void step(const RedCellTransport& red_cells, std::span<const double> inflow, Injection injected);
  // The same step in parts (RedCellTransport's, after its whole step): the cells no cut's
  // inflow reaches, then the rest once the cuts' inflows are given.
  void begin_step(const RedCellTransport& red_cells, std::span<const double> inflow, Injection injected);
  void solve(const RedCellTransport& red_cells, std::span<const double> inflow, Injection injected,
             RedCellTransport::Cells cells);
  void end_step(const RedCellTransport& red_cells, std::span<const double> inflow, Injection injected);
  // The concentration of the carrier crossing face f in the last step (or, between begin_step
  // and end_step, now): its upwind cell's, or its boundary's, and any injection there.
  double inflowing(std::size_t face, const RedCellTransport& red_cells, std::span<const double> inflow,
                   Injection injected) const;

  TracerCarrier carrier() const { return carrier_; }
  std::span<const double> concentration() const { return concentration_; }
  // The carrier of the red cells' last step (their CarrierStep for this tracer's carrier).
  CarrierStep carrier_step(const RedCellTransport& red_cells) const { return red_cells.carrier_step(carrier_); }
  // Its carrier in a cell now (after the last step, or the volumes set since).
  double carried(const RedCellTransport& red_cells, std::size_t cell) const;
  // Tracer in the network now (concentration x carrier volume), and through the boundaries
  // (each boundary's summed in their order) and injected since the start.
  double amount(const RedCellTransport& red_cells) const;
  double entered() const;
  double left() const;
  const std::vector<double>& entered_by_boundary() const { return entered_; }
  const std::vector<double>& left_by_boundary() const { return left_; }
  double injected() const { return injected_; }
  std::size_t bytes() const { return arrays_bytes(concentration_, last_outflow_, start_, entered_, left_); }
  // What the carrier's volumes moved between steps (the flow's compliance balance) added:
  // the caller adds, term by term, (carried after - before) x C of each cell as the volumes
  // move, and sets the total.
  double adjusted() const { return adjusted_; }
  void set_adjusted(double total) { adjusted_ = total; }

  // A cell of no faces that stands for another's (RedCellTransport::hold): the value sent.
  void hold(std::size_t cell, double concentration) { concentration_[cell] = concentration; }

  // The state as a checkpoint keeps it (entered and left per boundary).
  void restore(std::span<const double> concentration, std::span<const double> last_outflow,
               std::span<const double> entered, std::span<const double> left, double injected, double adjusted);
  const std::vector<double>& last_outflow() const { return last_outflow_; }

 private:
  double solve_cell(std::size_t cell, double start, const RedCellTransport& red_cells, const CarrierStep& m,
                    std::span<const double> inflow, Injection injected) const;

  TracerCarrier carrier_;
  std::vector<double> concentration_, last_outflow_;
  // The concentrations the step started from, of the cells solved more than once: per cell
  // on a grid with cuts, else the circulation's (the flow order's last `cyclic`) in that order.
  std::vector<double> start_;
  bool start_per_cell_ = false;
  // Cell c's, the k-th in flow order (its first `ordered` solved once without cuts).
  double step_start(std::size_t c, std::size_t k, std::size_t ordered) const;
  std::vector<double> entered_, left_;  // per boundary
  double injected_ = 0, adjusted_ = 0;
};

}  // namespace hemotree
