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
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "transport/red_cell_transport.hpp"

namespace hemotree {

enum class TracerCarrier { plasma, cells, blood };

class TracerTransport {
 public:
  TracerTransport(std::size_t cells, std::size_t boundaries, TracerCarrier carrier);

  // Advances the tracer over the red-cell transport's last step (call right after it).
  // inflow: per boundary, the concentration of the carrier it lets in (NaN: what last left
  // there). injected: per face, a concentration added to the carrier crossing it in this step
  // (empty: none), the injection's amount counted in injected().
  void step(const RedCellTransport& red_cells, std::span<const double> inflow, std::span<const double> injected);

  TracerCarrier carrier() const { return carrier_; }
  std::span<const double> concentration() const { return concentration_; }
  // Per face, the last step's tracer over the carrier through it (0 where none passed).
  std::span<const double> face_concentration() const { return face_concentration_; }
  // The carrier of a step (red cells' CarrierStep for this tracer's carrier).
  const CarrierStep& carrier_step(const RedCellTransport& red_cells) const;
  // Tracer in the network now, and through the boundaries and injected since the start
  // (concentration x carrier volume).
  double amount(const RedCellTransport& red_cells) const;
  double entered() const { return entered_; }
  double left() const { return left_; }
  double injected() const { return injected_; }
  // What the carrier's volumes moved between steps (the flow's compliance balance) added.
  double adjusted() const { return adjusted_; }

  // The totals as a checkpoint keeps them: entered, left, injected, adjusted, amount.
  std::vector<double> totals() const { return {entered_, left_, injected_, adjusted_, last_amount_}; }
  void restore(std::span<const double> concentration, std::span<const double> last_outflow,
               std::span<const double> totals);
  const std::vector<double>& last_outflow() const { return last_outflow_; }

 private:
  double inflowing(std::size_t face, const RedCellTransport& red_cells, std::span<const double> inflow,
                   std::span<const double> injected) const;
  double solve_cell(std::size_t cell, const RedCellTransport& red_cells, const CarrierStep& m,
                    std::span<const double> inflow, std::span<const double> injected) const;

  TracerCarrier carrier_;
  std::vector<double> concentration_, face_concentration_, last_outflow_;
  double entered_ = 0, left_ = 0, injected_ = 0, adjusted_ = 0, last_amount_ = 0;
};

}  // namespace hemotree
