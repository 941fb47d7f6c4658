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
//
// Over MPI ranks (docs/transport.md, "Over MPI ranks") each rank carries the cells of the 0D
// nodes it holds, the top's rank also the 1D vessels'; a root vessel between a share's node r
// and the top's node u is a face on both sides, to a cut (transport/transport_grid.hpp). A
// step solves first the cells no cut's inflow reaches; the shares send r's hematocrit and
// phase separation share up, the top solves the rest and sends u's down, the shares finish
// (flow_transport_ranks.cpp); the tracers then ride on that step with two messages of their
// own. Where the 1D vessels are spread over the ranks, each rank carries its own vessels'
// slices, its 0D nodes and every junction where it has an end; a vessel end across the cut
// is a face to a cut on the other side, and a step is solved in rounds, each rank's cells
// with the cuts' inflows of the round before, until no inflow changes
// (flow_transport_spread.cpp); a 0D system spread over the ranks is crossed the same way, each
// node's cell its owner's. Every cell's value is the one-process run's, bit for bit (where the
// 0D system is spread, to the flow's agreement with it); every sum of the cycle, the report and
// the checkpoint is taken on rank 0 in the one-process order.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <utility>
#include <optional>
#include <span>
#include <vector>

#include <Eigen/Dense>

#include "distributed/neighbour_exchange.hpp"
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

// A run over ranks: the top's rank and each rank's root vessels (LumpedCut::roots).
struct TransportRanks {
  int top_rank = 0;
  std::vector<int> roots;
};

class RootExchange;

class FlowTransport {
 public:
  // Call before the solver's first step (it starts the solver's face accumulators). ranks:
  // where the solver is a rank's part of a run over ranks; the constructor then takes no
  // collective call (so that a refusal on one rank can be made every rank's:
  // mpi/session.hpp's on_every_rank), and join_ranks, collective, completes it.
  FlowTransport(const Network& net, PulseSolver& solver, FlowTransportOptions options = {},
                const TransportRanks* ranks = nullptr);
  void join_ranks();
  // Not copied or moved: face_volume_ views its own red-cell transport's array.
  FlowTransport(const FlowTransport&) = delete;
  FlowTransport& operator=(const FlowTransport&) = delete;

  // Moves the red cells by what the solver passed since the last call (over ranks: collective).
  void advance();
  // After the solver's compliance balance moved its volumes: the cells take them.
  void take_volumes();
  // After the solver stepped without it (a settling cycle, solver/settling_cycle.hpp, whose
  // clock restarts at 0): the next advance counts from the solver's state and time now.
  void restart();
  // Over ranks these two are collective, and the cycle's numbers rank 0's (elsewhere partial).
  void begin_cycle();
  RedCellCycle close_cycle() const;

  const RedCellTransport& red_cells() const { return *red_cells_; }
  const std::vector<TracerSpec>& tracer_specs() const { return options_.tracers; }
  bool reports_red_cells() const { return options_.red_cells; }
  // Tracer k's numbers for the report: per vessel its curve's landmarks over the run so far,
  // and its balance (over ranks rank 0's, taken by take_reports before the ranks part).
  struct TracerReport {
    IndicatorCurves::Landmarks landmarks;
    double amount = 0, entered = 0, left = 0, injected = 0, adjusted = 0;
  };
  void take_reports();  // over ranks, collective: every rank at the run's end; alone nothing
  // At fraction x along a vessel (probes): the discharge hematocrit, and tracer k's
  // concentration, of the cell there (a 0D vessel: the node its blood came from last).
  double hematocrit_at(std::size_t vessel, double x) const;
  double tracer_at(std::size_t k, std::size_t vessel, double x) const;
  // The bytes this rank's transport holds: its grid, state, a step's arrays, the cycle's
  // sums, the tracers and their curves, the places of a cut (docs/transport.md, "Memory").
  std::size_t bytes() const;
  // The whole run's cells (over ranks: every rank's).
  std::size_t cell_count() const { return cut_ ? cut_->cells : red_cells_->grid().cell_count(); }
  // Over ranks: the exchange of its steps' messages (its traffic); else null.
  const RootExchange* exchange() const { return cut_ ? cut_->roots.exchange.get() : nullptr; }
  // Where the 1D vessels are spread: this rank's transport steps, their rounds (each a solve
  // of its cells and one message to each neighbouring rank), its messages and bytes, and the
  // seconds inside the exchanges and reductions (null otherwise).
  struct SpreadTraffic : NeighbourTraffic {
    std::size_t steps = 0, rounds = 0;
  };
  const SpreadTraffic* spread_traffic() const { return cut_ && cut_->spread ? &cut_->spread->traffic : nullptr; }

  // What the results read of the transport once the run is over and its state saved: the
  // tracers' reports (over ranks rank 0's, which take_reports took), the options and the
  // counts, so that the transport can be freed before the results are written (with red
  // cells and a tracer about 270 B a vessel). It takes the reports: the transport is spent.
  struct Outcome {
    std::vector<TracerSpec> tracers;
    std::vector<TracerReport> reports;  // per tracer
    bool red_cells = false;             // reported
    double pries_diameter_scale = 1;    // the blood's (the tube hematocrits)
    std::size_t cells = 0, advances = 0;
  };
  Outcome take_outcome();

  void save(CheckpointWriter& out) const;
  // Over ranks: the one-process run's bytes, written to `out` on rank 0, null elsewhere. Collective.
  void save_over_ranks(CheckpointWriter* out) const;
  // Over ranks every rank reads the whole run's checkpoint and takes its share.
  void restore(CheckpointReader& in);

 private:
  // The grid, as the constructor makes it: the 0D nodes' cells, the 1D vessels' slices and
  // junctions (and what meets each 1D end: (vessel, distal) -> cell or boundary side), the
  // faces; then the tracers where they are given.
  using EndSides = std::map<std::pair<std::int32_t, bool>, std::int32_t>;
  void add_node_cells(TransportGrid& grid, std::vector<double>& volume) const;
  EndSides add_one_d_cells(TransportGrid& grid, std::vector<double>& volume);
  // Returns, the 1D vessels spread, per 1D end with a face here: that face and the cell on
  // this side of the cut (an own vessel's end slice, or the junction or 0D node it meets here);
  // and where the 0D system is spread too, per end of a 0D vessel with a face here: that face
  // and the cell of the end's node (this rank's, or a ghost standing for its owner's).
  using EndFaces = std::map<std::pair<std::int32_t, bool>, std::pair<std::int32_t, std::int32_t>>;
  EndFaces add_faces(TransportGrid& grid, const std::vector<std::int32_t>& roots, const EndSides& sides);
  void set_up_tracers();
  double fahraeus(double diameter) const;  // the Fahraeus parameter k of a lumen (1: the effect off)
  // Each 0D node's and 1D slice's volume in the solver now, into its cell's place.
  void solver_volumes(std::vector<double>& volume) const;
  // The same of the 1D slices alone, slice cell c's at volume[c - first].
  void slice_volumes(std::span<double> volume, std::size_t first) const;
  void mark();  // the next advance counts from the solver's state now
  std::size_t cell_at(std::size_t vessel, double x) const;
  void step_tracers(double t0, double t1);
  void face_volumes();  // face_volume_ from what the solver passed since the last advance
  // Tracer k's inflow per boundary and injection per face over [t0, t1], into its arrays.
  void tracer_given(std::size_t k, double t0, double t1);
  void follow_curve(std::size_t k, double t0, double t1);  // each vessel's curve after a step
  // The red cells in the network, through the boundaries (in, out) and added by the volumes'
  // changes since the start (over ranks: rank 0's, collective).
  struct Totals {
    double red_cells, entered, left, adjusted;
  };
  Totals totals() const;
  void close_step();    // the cycle's sums and the viscosities after a step

  // Over ranks: where every cell, face and boundary of this rank lies in the whole run's grid
  // (the one-process order), and the cut of the flow's layout, a tree's roots or the links of
  // the spread vessels.
  struct Cut {
    std::size_t run_boundaries = 0;   // the network's (the grid's first ones)
    std::vector<std::int32_t> cell_place, face_place;  // in the whole run's grid
    std::vector<signed char> face_sign;  // per face: +1, or -1 where a cut turned it round
    std::size_t cells = 0, faces = 0;    // the whole run's
    // The cells held here whose numbers are another rank's (a junction where it has an end
    // too, a ghost node of a spread 0D system).
    std::vector<std::int32_t> copies;
    // A tree's top and shares (flow_transport_ranks.cpp): a face per root vessel, to a cut on
    // either side, crossed by two messages a step.
    struct Roots {
      bool top = false;
      std::shared_ptr<RootExchange> exchange;
      std::vector<std::int32_t> face;   // per root (the messages' order): its face here
      std::vector<std::int32_t> cell;   // the cell on this side of it
      std::vector<std::int32_t> across; // the empty cell of the node across it
      std::vector<double> far;          // the hematocrit of the cell across it (a share's probes)
      std::vector<double> tracer_far;   // per tracer, per root: its concentration there
      std::vector<std::int32_t> ghost;  // per node cell: the root it is the node across (-1: its own)
    } roots;
    // The 1D vessels spread, and a 0D system with them (flow_transport_spread.cpp): per
    // neighbouring rank the faces whose numbers go there (with the cell on this side) and the
    // cut faces taken from there, each in the run's order of vessel ends, and whether each
    // carries the face's volume (sent by the vessel's rank); the tracers' last inflows at the
    // cuts (per tracer, per cut); the exchanges' traffic. None where the layout is a tree's.
    struct Links {
      struct Neighbour {
        int rank = 0;
        std::vector<std::int32_t> send_face, send_cell, receive_face;
        std::vector<unsigned char> send_volume, receive_volume;
        // Per received link, the cell here that stands for the sender's (a ghost node of a
        // spread 0D system, which takes the sent values), or -1.
        std::vector<std::int32_t> receive_cell;
      };
      std::vector<Neighbour> neighbours;
      std::size_t count = 0;  // the whole run's links
      std::vector<double> tracer_in;
      SpreadTraffic traffic;
    };
    std::optional<Links> spread;
  };
  // The cut's faces were made with the grid; the rest of the Cut from them.
  void place_cut(const TransportRanks& ranks);
  // The one-process grid's 0D part, where both cuts place theirs: its first cells, the 0D
  // nodes in pulse/lumped_order's order (node_place per network node, nodes of them); its
  // first faces, the 0D vessels in the network's order, then the boundaries at 0D nodes
  // (zero_d_faces + boundary_place[b]); the 1D faces after them (one_d_faces).
  struct ZeroDPlaces {
    std::vector<bool> zero_d;  // per vessel
    std::size_t nodes = 0;
    std::vector<std::int32_t> node_place, zero_d_before, boundary_place;
    std::int32_t zero_d_faces = 0, one_d_faces = 0;
    // A 0D vessel's or a boundary's face f of the grid, at its place (-1: a 1D vessel's).
    std::int32_t face_place(const TransportGrid& grid, std::size_t f) const;
  };
  ZeroDPlaces zero_d_places() const;
  void advance_over_ranks();
  // A step's two messages across the cuts, per_root numbers a root each way: `here` gives this
  // side's (the shares' up, then the top's down), `across` takes the other side's as the cuts'
  // inflows, `rest` solves what waited for them. failure: this rank's before the messages;
  // it, or the top's in `rest`, is thrown on every rank. Collective.
  void across_cuts(std::size_t per_root, std::exception_ptr failure, const char* what,
                   const std::function<std::vector<double>()>& here,
                   const std::function<void(std::span<const double>)>& across, const std::function<void()>& rest);
  void step_tracers_over_ranks(double t0, double t1);
  // The 1D vessels spread (flow_transport_spread.cpp): the run's 1D vessels in the
  // one-process grid's order; the cut's places and messages once the grid is made; a step.
  std::vector<std::int32_t> whole_one_d_order() const;
  void place_spread_cut(const EndFaces& end_faces);
  void advance_spread();
  void step_tracers_spread(double t0, double t1);
  // Each cut face's volume from the vessel's rank (into face_volume_).
  void take_cut_volumes();
  // Solves `solve` in rounds, each after the cuts' inflows of the last (per_link numbers a
  // link: `here` writes this side's of a sent face, `across` takes the other side's of a
  // received one, with the cell here that stands for the sender's or -1, and returns how far
  // they moved, 0 for the same bits), until none moves on any rank. Collective.
  void spread_rounds(std::size_t per_link, const char* what, const std::function<void(RedCellTransport::Cells)>& solve,
                     const std::function<void(std::size_t face, std::size_t cell, double* numbers)>& here,
                     const std::function<double(std::size_t face, std::int32_t held, const double* numbers)>& across);
  // A node's cell that holds no blood here: across a tree's cut, or a ghost of a spread 0D system.
  bool empty_node_cell(std::size_t cell) const;
  // Numbers out to each neighbouring rank and in from it, of the sizes both sides know.
  void exchange_numbers(const std::vector<std::vector<double>>& out, std::vector<std::vector<double>>& in);

  std::vector<TracerReport> reports_;  // over ranks, rank 0's (take_reports)
  TracerReport tracer_report(std::size_t k) const;  // alone
  // On rank 0 `start` plus each of the whole run's items in turn (per cell or boundary: each
  // rank's values at `place`, -1 none), in the one-process order; elsewhere `start`. Collective.
  double lead_sum(std::span<const double> values, std::span<const std::int32_t> place, std::size_t whole,
                  double start) const;
  // The sum over the whole run's cells of per_cell (this rank's), from start, in the
  // one-process order: alone in turn, over ranks on rank 0 (elsewhere start).
  double cell_sum(std::span<const double> per_cell, double start) const;
  // The same items whole on rank 0 (elsewhere empty).
  std::vector<double> lead_whole(std::span<const double> values, std::span<const std::int32_t> place,
                                 std::size_t whole) const;
  // The places of what this rank holds for its own (-1: what another rank holds, the cells
  // and faces across a cut): per cell, per face, per boundary of the grid.
  std::vector<std::int32_t> own_cell_places() const;
  std::vector<std::int32_t> own_face_places() const;
  std::vector<std::int32_t> boundary_places() const;
  // The vessels it steps, increasing; and their places in `arrays` arrays of one number a
  // vessel one after the other (a tracer's curves), array after array: what it sends of such
  // arrays is its own vessels' values alone, not an array the network's size.
  std::vector<std::int32_t> own_vessels() const;
  std::vector<std::int32_t> own_vessel_places(std::span<const std::int32_t> own, std::size_t arrays) const;
  double rank_sum(double value) const;  // on rank 0 every rank's value, summed in rank order
  void close_cycle_over_ranks(RedCellCycle& c) const;
  // The red cells' state as a checkpoint holds it, in the one-process grid's order: per cell,
  // per boundary of the network, per vessel, per face.
  struct RedCellState {
    std::vector<double> discharge, volume, entered, left;
    double adjusted = 0;
    std::vector<double> last_outflow, applied, faces;
  };
  static void put_red_cells(CheckpointWriter& out, const RedCellState& state);
  RedCellState get_red_cells(CheckpointReader& in) const;  // its sizes checked
  void restore_share(const RedCellState& whole);
  // A tracer's state as a checkpoint holds it (the same order; its curves per vessel, six
  // arrays one after the other).
  struct TracerState {
    std::vector<double> concentration, last_outflow, entered, left;
    double injected = 0, adjusted = 0;
    std::vector<double> curve;
  };
  static void put_tracer(CheckpointWriter& out, const TracerState& state);
  TracerState get_tracer(CheckpointReader& in, std::size_t k) const;  // its sizes checked
  void restore_tracer_share(std::size_t k, const TracerState& whole);

  const Network& net_;
  PulseSolver& solver_;
  FlowTransportOptions options_;
  // 1D vessels: per 1D vessel (one_d_'s order) its first slice cell and its faces, the
  // proximal face first; per slice the element and its row of the slice integrals.
  std::vector<std::int32_t> vessel_first_cell_, vessel_first_face_;
  std::vector<signed char> proximal_sign_;  // +1: the proximal face runs along the vessel
  int slices_ = 1;
  Eigen::MatrixXd slice_integral_;  // slices x modes: int of P_j over each slice of [-1, 1]
  // 0D vessels: their faces (in LumpedVessels' order).
  std::vector<std::int32_t> lumped_face_;
  std::vector<std::int32_t> one_d_;        // the 1D vessels it carries (over ranks the top's rank's)
  // Each 1D vessel's place in one_d_, by vessel (few: looked up, not an array the network's size).
  std::vector<std::pair<std::int32_t, std::int32_t>> one_d_by_vessel_;
  std::int32_t one_d_place(std::size_t vessel) const;  // -1: not one of them
  // The boundaries at 0D nodes: their faces, one after another (first, count), each to its boundary.
  std::pair<std::int32_t, std::int32_t> node_boundary_faces_{0, 0};
  std::vector<double> inflow_hematocrit_;  // per boundary (NaN: what last left there)
  // The boundaries' volumes at the last advance (the solver's own sums, never cleared).
  Eigen::VectorXd boundary_mark_;
  // The last step's blood per face (checkpointed: cell_at reads its signs), the red-cell
  // transport's own array (RedCellTransport::face_volumes), filled here for each step.
  std::span<double> face_volume_;
  std::vector<double> slice_volume_;  // scratch: the 1D slices' volumes, from the first slice's cell
  std::optional<RedCellTransport> red_cells_;
  std::size_t advances_ = 0;
  // The cycle in progress, per vessel: red cells and blood through its faces, extremes.
  std::vector<double> cycle_cells_, cycle_blood_, cycle_low_, cycle_high_;
  // The viscosity feedback: per vessel the hematocrit its factor was computed at, the factor.
  std::vector<double> applied_hematocrit_;
  std::vector<HematocritScaling> viscosity_scaling_;  // per vessel
  void follow_viscosities(std::size_t vessel, double hematocrit);  // one vessel's factor
  double cycle_content_ = 0, cycle_entered_ = 0, cycle_left_ = 0, cycle_adjusted_ = 0;
  // Tracers: their transport, curves, and where each is given (boundaries, or a face).
  std::vector<TracerTransport> tracers_;
  std::vector<IndicatorCurves> curves_;
  std::vector<std::vector<std::int32_t>> tracer_boundaries_;
  std::vector<std::int32_t> tracer_face_;  // -1: none here (over ranks: another rank's vessel)
  std::vector<std::vector<double>> tracer_inflow_;  // per tracer, of a step
  std::vector<Injection> tracer_injected_;
  double last_time_ = 0;  // the solver's time at the last advance
  std::optional<Cut> cut_;
};

}  // namespace hemotree
