// Red cells through a pulsatile run: the transport grid of a PulseSolver's network, and the
// volumes the solver passed through its faces, handed to the red-cell transport every few
// steps (docs/transport.md).
//
// Cells: every node of 0D vessels (the 0D model's node volumes, half of each vessel there),
// `slices` slices of every 1D element (the integral of the element's area polynomial over
// each), and every junction of 1D vessels (no volume). Faces: every 0D vessel (what it
// passed, dt Q at each step's end: the flows BDF2 balances its nodes with), the ends and
// slice boundaries of every 1D vessel, and every boundary condition at a node of 0D vessels.
// A 1D vessel's proximal face passes the time integral of its numerical flux (the state's
// own accumulator, integrated by the solver's scheme); each slice face after it passes that
// less the change of the slices before it, so that every slice ends the step holding the
// solver's own volume. Everything the 0D nodes hold is theirs exactly too (BDF2's stored
// volume), so the transport's volumes never drift from the flow's.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Dense>

#include "formats/network.hpp"
#include "physics/rheology.hpp"
#include "formats/checkpoint_file.hpp"
#include "pulse/pulse_solver.hpp"
#include "solver/tracer_spec.hpp"
#include "transport/indicator_curves.hpp"
#include "transport/red_cell_transport.hpp"
#include "transport/tracer_transport.hpp"

namespace hemotree {

struct FlowTransportOptions {
  bool red_cells = true;         // reported (false: fixed, carriers of tracers only)
  int slices = 0;                // per 1D element; 0: its degree + 1
  bool phase_separation = true;  // at diverging nodes (else mixed by flux everywhere)
  bool fahraeus = true;          // tube hematocrit below discharge hematocrit in small vessels
  // Each vessel's viscosity at its own discharge hematocrit, followed step by step (a vessel's
  // is computed again when its hematocrit has moved by more than viscosity_tolerance).
  bool viscosity_feedback = true;
  double viscosity_tolerance = 1e-4;
  // Indicators carried along (--tracer). With the red cells fixed (all three flags above
  // false) the cells still move, uniformly, as the tracers' carriers.
  std::vector<TracerSpec> tracers;
};

// What the red cells do with the flags: transported (phase separation, Fahraeus, viscosity)
// or fixed (a uniform carrier for tracers).
FlowTransportOptions red_cells_fixed(FlowTransportOptions options);

// Per vessel over one cycle: the red cells it passed over the blood it passed (the cycle's
// discharge hematocrit), and the lowest and highest discharge hematocrit of a step.
struct RedCellCycle {
  std::vector<double> discharge, lowest, highest;
  double red_cells = 0;            // in the network at the cycle's end [m^3]
  double entered = 0, left = 0;    // through the boundaries during the cycle [m^3]
  double balance_error = 0;        // (change - (in - out)) / (in + content), round-off
  std::size_t separating_nodes = 0;  // where the law split red cells at the cycle's last step
};

class FlowTransport {
 public:
  // Call before the solver's first step (it starts the solver's face accumulators).
  FlowTransport(const Network& net, PulseSolver& solver, FlowTransportOptions options = {});

  // Moves the red cells by what the solver passed since the last call.
  void advance();
  // After the solver's compliance balance moved its volumes: the cells take them.
  void take_volumes();
  // After the solver stepped without it (a settling cycle, solver/settling_cycle.hpp, whose
  // clock restarts at 0): the next advance counts from the solver's state and time now.
  void restart();
  void begin_cycle();
  RedCellCycle close_cycle() const;


  const RedCellTransport& red_cells() const { return *red_cells_; }
  const std::vector<TracerSpec>& tracer_specs() const { return options_.tracers; }
  bool reports_red_cells() const { return options_.red_cells; }
  const Blood& red_cells_blood() const { return solver_.blood(); }
  const TracerTransport& tracer(std::size_t k) const { return tracers_[k]; }
  // Per vessel, tracer k's curve landmarks over the run so far.
  IndicatorCurves::Landmarks tracer_landmarks(std::size_t k) const { return curves_[k].landmarks(solver_.time()); }
  // At fraction x along a vessel (probes): the discharge hematocrit, and tracer k's
  // concentration, of the cell there (a 0D vessel: the node its blood came from last).
  double hematocrit_at(std::size_t vessel, double x) const;
  double tracer_at(std::size_t k, std::size_t vessel, double x) const;
  std::size_t cell_count() const { return red_cells_->grid().cell_count(); }
  std::size_t advances() const { return advances_; }

  void save(CheckpointWriter& out) const;
  void restore(CheckpointReader& in);

 private:
  // Each 0D node's and 1D slice's volume in the solver now, into its cell's place.
  void solver_volumes(std::vector<double>& volume) const;
  void mark();  // the next advance counts from the solver's state now
  std::size_t cell_at(std::size_t vessel, double x) const;
  void step_tracers(double t0, double t1);

  const Network& net_;
  PulseSolver& solver_;
  FlowTransportOptions options_;
  // 1D vessels: per 1D vessel (one_d_vessels' order) its first slice cell and its faces, the
  // proximal face first; per slice the element and its row of the slice integrals.
  std::vector<std::int32_t> vessel_first_cell_, vessel_first_face_;
  std::vector<signed char> proximal_sign_;  // +1: the proximal face runs along the vessel
  int slices_ = 1;
  Eigen::MatrixXd slice_integral_;  // slices x modes: int of P_j over each slice of [-1, 1]
  // 0D vessels: their faces (in LumpedVessels' order); boundaries at 0D nodes: face and boundary.
  std::vector<std::int32_t> lumped_face_;
  std::vector<std::int32_t> one_d_place_;  // per vessel: its place in one_d_vessels, or -1
  std::vector<std::int32_t> node_boundary_face_, node_boundary_;
  std::vector<double> inflow_hematocrit_;  // per boundary (NaN: what last left there)
  // The boundaries' volumes at the last advance (the solver's own sums, never cleared).
  Eigen::VectorXd boundary_mark_;
  std::vector<double> face_volume_;  // the last step's, per face (checkpointed: cell_at reads its signs)
  std::vector<double> now_;          // scratch
  std::optional<RedCellTransport> red_cells_;
  std::size_t advances_ = 0;
  // The cycle in progress, per vessel: red cells and blood through its faces, extremes.
  std::vector<double> cycle_cells_, cycle_blood_, cycle_low_, cycle_high_;
  std::vector<double> step_sum_;
  // The viscosity feedback: per vessel the hematocrit its factor was computed at, the factor.
  std::vector<double> applied_hematocrit_;
  std::vector<HematocritScaling> viscosity_scaling_;  // per vessel
  void follow_viscosities(std::size_t vessel, double hematocrit);  // one vessel's factor
  std::vector<std::int32_t> step_count_;
  double cycle_content_ = 0, cycle_entered_ = 0, cycle_left_ = 0, cycle_adjusted_ = 0;
  // Tracers: their transport, curves, and where each is given (boundaries, or a face).
  std::vector<TracerTransport> tracers_;
  std::vector<IndicatorCurves> curves_;
  std::vector<std::vector<std::int32_t>> tracer_boundaries_;
  std::vector<std::int32_t> tracer_face_;
  std::vector<double> tracer_inflow_, tracer_injected_;  // scratch
  double last_time_ = 0;  // the solver's time at the last advance
};

}  // namespace hemotree
