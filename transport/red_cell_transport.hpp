// Red cells carried by the pulsatile flow: the discharge hematocrit H_D of every cell of a
// TransportGrid, advanced by implicit upwind finite volumes (docs/transport.md).
//
// A cell holds red cells V H_T, its tube hematocrit (the Fahraeus effect: H_T = H_D (k +
// (1 - k) H_D), k of its lumen); blood leaving it carries them at H_D, the red cells' mean
// velocity being faster than the blood's by H_D / H_T. Per step, for each cell in flow order,
//   V+ H_T(H_D+) + Q_out H_D+ = V H_T(H_D) + sum_in Q_f s_f H_D,upwind(f)
// with Q the blood volumes the faces passed, V+ = V + Q_in - Q_out, and s_f the share of the
// red cells a diverging node sends into face f over that face's share of the blood (Pries &
// Secomb 2005: FQE / FQB; 1 elsewhere). The left side increases in H_D+, so each cell is one
// quadratic; the right side is a convex combination of values in [0, 1) (with V >= 0 and
// s_f H <= 1), so 0 <= H_D+ < 1 whatever the step: no CFL limit, no new extrema but those the
// phase separation makes, and every red cell that leaves a cell enters the next: the content
// sum V H_T changes by what the boundaries let in and out, to round-off.
//
// Phase separation is applied at a node cell with no boundary where this step's flow enters
// through one vessel and leaves through two (the law's own case, with the feed's hematocrit
// of the step before); blood is mixed by flux everywhere else, and at a node of more than
// three vessels too (NetFlow's dishem.cpp rule; steady/steady_hematocrit.hpp does the same).
// A cut of the grid (transport/transport_grid.hpp) counts as the vessel it stands in for there.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/array_bytes.hpp"
#include "transport/transport_grid.hpp"

namespace hemotree {

struct RedCellOptions {
  bool phase_separation = true;
  double diameter_scale = 1;  // what the phase separation law multiplies diameters by
};

// What a tracer rides on (transport/tracer_transport.hpp).
enum class TracerCarrier { plasma, cells, blood };

class CarrierStep;

class RedCellTransport {
 public:
  // volume: per cell [m^3] (junctions 0); hematocrit: the discharge hematocrit everywhere at
  // the start. Throws InputError for sizes that do not match the grid, a negative volume or
  // a hematocrit outside [0, 1).
  RedCellTransport(TransportGrid grid, std::vector<double> volume, double hematocrit, RedCellOptions options = {});

  // Advances one step. face_volume: the blood each face passed [m^3]; inflow_hematocrit: per
  // boundary, the discharge hematocrit of blood it lets in (NaN: what last left through it,
  // the starting hematocrit until something has).
  void step(std::span<const double> face_volume, std::span<const double> inflow_hematocrit);

  // The same step in parts, for a grid with cuts (a run over ranks): begin, solve the cells
  // that no cut's inflow reaches (`before_cuts`: what the other side's cells wait for), give
  // each cut its inflow, solve the rest (`after_cuts`), end. Each cell's new value is the one
  // step() gives: its upwind cells are solved before it either way. face_volume and
  // inflow_hematocrit as step()'s, the same in every part (the cuts' inflows read in
  // after_cuts only).
  enum class Cells { all, before_cuts, after_cuts };
  void begin_step(std::span<const double> face_volume);
  void solve(std::span<const double> face_volume, std::span<const double> inflow_hematocrit, Cells cells);
  void end_step(std::span<const double> face_volume, std::span<const double> inflow_hematocrit);
  // Of this step (after begin_step): the phase separation's share s_f of a face, the red
  // cells' over the blood's there (1 but where a node divides its blood): blood leaving a cell
  // c through f carries s_f H_D(c).
  double separation_share(std::size_t face) const { return share_[face]; }
  // Of this step: whether a cut's inflow reaches a cell (solved after_cuts; never without cuts).
  bool after_cut(std::size_t cell) const { return !after_cut_.empty() && after_cut_[cell] != 0; }
  // Which of a step's parts solves a cell.
  bool solves(std::size_t cell, Cells cells) const {
    return cells == Cells::all || after_cut(cell) == (cells == Cells::after_cuts);
  }

  // Replaces the cells' volumes (the flow solver's moved them: its compliance balance),
  // keeping their hematocrits; the red cells that adds or removes are kept in adjusted().
  void set_volumes(std::span<const double> volume);
  void set_hematocrit(std::span<const double> discharge);
  // A cell of no faces that stands for another's (over ranks, a node its owner solves): the
  // value it was sent. A step keeps it, as it keeps any cell nothing flows through.
  void hold(std::size_t cell, double discharge) { discharge_[cell] = discharge; }
  // The whole state, as a checkpoint holds it (sizes checked by the caller): entered and left
  // per boundary.
  void restore(std::span<const double> discharge, std::span<const double> volume, std::span<const double> entered,
               std::span<const double> left, double adjusted, std::span<const double> last_outflow);
  // Per boundary: the discharge hematocrit that last left through it.
  const std::vector<double>& last_outflow() const { return last_outflow_; }

  const TransportGrid& grid() const { return grid_; }
  const CellFaces& faces() const { return faces_; }
  const FlowOrder& order() const { return order_; }
  std::span<const double> discharge_hematocrit() const { return discharge_; }
  std::span<const double> volume() const { return volume_; }
  double tube_hematocrit(std::size_t cell) const { return tube(cell, discharge_[cell]); }
  // Red cells in the network now, sum V H_T [m^3] (a cell's: content()); through the
  // boundaries since the start (in, out) [m^3], each boundary's summed in their order (cuts
  // are no boundary of the network: none through them); added by set_volumes.
  double red_cells() const;
  double content(std::size_t cell) const { return volume_[cell] * tube(cell, discharge_[cell]); }
  double entered() const;
  double left() const;
  const std::vector<double>& entered_by_boundary() const { return entered_; }
  const std::vector<double>& left_by_boundary() const { return left_; }
  double adjusted() const { return adjusted_; }
  // The total a run over ranks sums in the one-process order (solver/flow_transport.hpp).
  void set_adjusted(double total) { adjusted_ = total; }
  // The last step (end_step's, until the next begin_step): per face the blood and the red
  // cells it passed (signed as the blood's) [m^3], per cell the blood and the red cells in it
  // before the step and after it. The red cells after it and every plasma number follow
  // from what is kept, as the step formed them: with tracers, a tree's million cells hold
  // about 50 MB less than with each carrier's three arrays kept.
  std::span<const double> blood_through() const { return blood_face_; }
  // The same array to fill with the next step's blood per face and hand to step() (or its
  // parts), so that a caller keeps no copy of its own (until then it holds the last step's).
  std::span<double> face_volumes() { return blood_face_; }
  std::span<const double> cells_through() const { return cells_face_; }
  double blood_before(std::size_t c) const { return next_volume_[c]; }  // end_step swapped them
  double blood_after(std::size_t c) const { return volume_[c]; }
  double cells_before(std::size_t c) const { return cells_before_[c]; }
  double cells_after(std::size_t c) const { return volume_[c] * tube(c, discharge_[c]); }
  CarrierStep carrier_step(TracerCarrier carrier) const;
  // Cells where the phase separation law split the red cells in the last step.
  std::size_t separating_nodes() const { return separating_.size(); }
  std::span<const std::int32_t> separating_cells() const { return separating_; }
  // The bytes it holds: the grid and its order, the state and a step's arrays.
  std::size_t bytes() const {
    return grid_.bytes() + faces_.bytes() + order_.bytes() +
           arrays_bytes(volume_, next_volume_, discharge_, share_, candidates_, last_outflow_, after_cut_, blood_face_,
                        cells_face_, cells_before_, entered_, left_, separating_);
  }

 private:
  double tube(std::size_t cell, double discharge) const {
    const double k = grid_.fahraeus[cell];
    return discharge * (k + (1 - k) * discharge);
  }
  // The phase separation shares s_f of this step's faces (1 where blood is mixed).
  void split_at_nodes(std::span<const double> face_volume);
  // The new H_D of a cell from its neighbours' values now; returns it.
  double solve_cell(std::size_t cell, std::span<const double> face_volume, std::span<const double> inflow_hematocrit);
  double face_hematocrit(std::size_t face, std::span<const double> face_volume,
                         std::span<const double> inflow_hematocrit) const;

  TransportGrid grid_;
  CellFaces faces_;
  FlowOrder order_;
  RedCellOptions options_;
  std::vector<double> volume_, next_volume_, discharge_;
  std::vector<double> share_;            // per face: s_f of this step
  std::vector<std::int32_t> candidates_;  // node cells of three vessels and no boundary
  std::vector<double> last_outflow_;     // per boundary: the hematocrit that last left there
  // Per cell, with cuts: whether a cut's inflow reaches it this step (solved after_cuts).
  std::vector<unsigned char> after_cut_;
  std::vector<double> blood_face_, cells_face_, cells_before_;  // the last step's (above)
  // Per boundary, red cells in and out through it since the start: summed at the end in the
  // boundaries' order, so that ranks holding a few each give the one-process sum.
  std::vector<double> entered_, left_;
  double adjusted_ = 0;
  std::vector<std::int32_t> separating_;  // the cells where it did
};

// What a step moved of one carrier (red cells, plasma or whole blood): the volume of it each
// face passed (signed as the blood's), and each cell's content before and after the step.
// Its balance closes per cell: after + out = before + in. Tracers ride on it. A view of the
// red-cell transport's last step: valid until its next.
class CarrierStep {
 public:
  CarrierStep(const RedCellTransport& red_cells, TracerCarrier carrier) : red_cells_(red_cells), carrier_(carrier) {}
  double face(std::size_t f) const { return of(red_cells_.blood_through()[f], red_cells_.cells_through()[f]); }
  double before(std::size_t c) const { return of(red_cells_.blood_before(c), red_cells_.cells_before(c)); }
  double after(std::size_t c) const { return of(red_cells_.blood_after(c), red_cells_.cells_after(c)); }

 private:
  // The carrier's part of blood that holds red cells: the plasma is the rest.
  double of(double blood, double cells) const {
    switch (carrier_) {
      case TracerCarrier::plasma:
        return blood - cells;
      case TracerCarrier::cells:
        return cells;
      case TracerCarrier::blood:
        break;
    }
    return blood;
  }
  const RedCellTransport& red_cells_;
  TracerCarrier carrier_;
};

inline CarrierStep RedCellTransport::carrier_step(TracerCarrier carrier) const { return {*this, carrier}; }

}  // namespace hemotree
