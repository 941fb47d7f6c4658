// The 0D (lumped) vessels of a network, advanced together, implicitly, by BDF2.
//
// A vessel much shorter than the pulse's wavelength holds no travelling wave: its flow is
// quasi-steady, one number along it. Each such vessel is a pi circuit: its compliance
// C = L dA/dp (tube law, at the current pressure) split between its two nodes, and between
// them its resistance in series with its inertance rho L / A. The resistance is that of a
// compliant tube in steady flow, (p_a - p_b) / Q with Q = (1/L) int A^2 / (k mu(A)) dp from
// p_b to p_a (Simpson): Poiseuille's k mu(A) L / A^2 (the run's viscosity and velocity profile,
// k = 2 pi alpha / (alpha - 1), as in the 1D friction) where the lumen is uniform, and right
// where the pressure drop narrows the lumen along the vessel (the narrowest capillaries).
// The state is the volume at every node (half of each adjacent 0D vessel's) and the flow in
// every vessel: volume is the conserved variable, so mass is conserved to round-off whatever
// the nonlinear iteration leaves.
//
// A vessel along which the pressure diffuses (a long capillary: w R C above what one pi
// circuit follows) may be a chain of n equal pi sections instead, with n - 1 nodes of its own
// inside it: the same element on L / n, whose error falls as 1 / n^2 (docs/solver.md §10).
// Its sections are edges side by side in the arrays (the first at `from`), its inner nodes
// come after the capacitor nodes.
//
// BDF2 (L-stable: L / R, nanoseconds in a capillary, lies far below the step, and is damped
// rather than resolved) with the flows eliminated leaves one system in the node pressures,
// the weighted Laplacian plus C/dt of network_flow/nodal_system: on a tree, O(nodes) per
// step. The nonlinear R(A), L(A) and C(p) are taken at the state extrapolated to the step's
// end (2 x^n - x^(n-1): linearly implicit BDF2, second order with one solve a step); each
// further Picard pass (`passes`) takes them again at the last solution. The solve is split
// in its forward and backward halves around the 1D substeps (network_flow), and every node
// sums its edges by a gather, in one order whatever the threads: the loops are bound by
// memory bandwidth, so each is written to read a node's or a vessel's row once.
//
// Boundary conditions at nodes of 0D vessels are part of the system (an outlet R: a shunt
// to p_out; RCR: R1 to a capacitor node, R2 from there to p_out; a flow: a current into the
// node; a pressure: a shunt stiff enough to hold the node there). A 1D vessel end at a node of 0D vessels is a
// coupling end: the 1D vessel sees the node's pressure, and the node receives the volume the
// 1D scheme let through that end (docs/solver.md §10).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "core/parallel_errors.hpp"
#include "formats/network.hpp"
#include "network_flow/nodal_system.hpp"
#include "physics/viscosity_table.hpp"
#include "formats/checkpoint_file.hpp"
#include "physics/vessel_taper.hpp"
#include "pulse/lumped_cut.hpp"
#include "pulse/lumped_halo.hpp"
#include "pulse/lumped_order.hpp"

namespace hemotree {

class LumpedVessels {
 public:
  // A step's linearisation found a node whose compliance is not positive (a lumen closing
  // at the state the step is taken at): the network vessel named, for the caller to report.
  struct CollapsedNode {
    std::int32_t vessel;
  };
  LumpedVessels() = default;  // none
  // zero_d: per vessel, whether it is 0D. Throws InputError for a reflection outlet on a 0D
  // vessel (it needs the waves of a 1D one).
  // taper_of: per vessel, its index in tapers or -1 (empty: no vessel tapers). A tapered 0D
  // vessel (docs/solver.md §10) holds int A(p, x) dx, still a quadratic in p; its resistance
  // is int k mu(A) / A^2 dx along the rigid taper's pressure profile, its inertance
  // rho int dx / A.
  // sections: per vessel, the pi sections of a 0D one (0 or 1: one; empty: all one). A
  // tapered vessel takes one.
  // cut: where given, one rank's part of a run over ranks (pulse/lumped_cut.hpp: its vessels
  // and their nodes in the whole run's order, the top's rank with the other ranks' root vessels
  // as ghosts), whose steps exchange their messages through set_link's link; else every 0D
  // vessel, in pulse/lumped_order's subtree order.
  // halo: where given instead, one rank's part of a 0D system with loops over ranks
  // (pulse/lumped_halo.hpp: its vessels and the halo of other ranks' at its nodes), whose
  // steps are solved through set_halo_link's link.
  LumpedVessels(const Network& net, std::span<const TubeLaw> laws, const ViscosityTable& viscosity,
                const Blood& blood, const std::vector<bool>& zero_d, std::span<const std::int32_t> taper_of = {},
                std::span<const VesselTaper> tapers = {}, std::span<const std::uint8_t> sections = {},
                const LumpedCut* cut = nullptr, const LumpedHalo* halo = nullptr);
  // Solves a step takes (1: the extrapolated linearisation alone; the only one over ranks,
  // std::invalid_argument for more), and the threads of its loops over vessels and nodes and
  // of the elimination's subtrees.
  void set_passes(int passes);
  void set_threads(int threads) {
    threads_ = threads;
    system_.set_threads(threads);
  }

  bool empty() const { return vessels_.empty(); }
  std::size_t vessel_count() const { return vessels_.size(); }
  std::size_t network_vessel(std::size_t index) const { return static_cast<std::size_t>(vessels_[index]); }  // its network index
  std::size_t node_count() const { return nodes_; }  // network nodes of 0D vessels, capacitors, inner nodes
  // Whether any 0D vessel is more than one pi section (then inner nodes hold volume that no
  // network node does: a transport of the network's nodes cannot take it).
  bool sectioned() const { return !first_edge_.empty(); }
  // The pi sections of 0D vessel `index`.
  std::size_t sections(std::int32_t index) const {
    const auto i = static_cast<std::size_t>(index);
    return first_edge_.empty() ? 1 : static_cast<std::size_t>(first_edge_[i + 1] - first_edge_[i]);
  }
  // Its node for a network node, or -1 where no 0D vessel ends.
  std::int32_t node_of(std::int64_t network_node) const { return node_of_[static_cast<std::size_t>(network_node)]; }
  // The boundary flows and pressures at its nodes, by their places in the run's list
  // (formats/run_boundaries.hpp): predict() takes their values in these orders.
  const std::vector<std::int32_t>& inflow_boundaries() const { return inflow_boundary_; }
  const std::vector<std::int32_t>& held_boundaries() const { return held_boundary_; }
  // Every boundary of the run's list at its nodes (flows, pressures, outlets), increasing:
  // over ranks, the boundaries this rank holds.
  std::vector<std::int32_t> boundaries() const;


  // Initial states: every node at the given pressure of its network node (steady: the steady
  // solution; rest: reference pressures), vessels at the given flows; capacitors at
  // p - R1 Q of their vessel's end (R1 edges and outlets follow from the pressures).
  void start(const std::vector<double>& network_node_pressure, const std::vector<double>& vessel_flow);
  void start_at_rest(std::span<const TubeLaw> laws);
  // The state of another of the same network, models and sections (built alike: the same
  // nodes and edges in the same order), its pressures and flows as they are, the history
  // restarting from them (std::invalid_argument for one built otherwise).
  void start_from(const LumpedVessels& other);

  // The nodes where 1D vessel ends meet 0D vessels (each once).
  void set_coupling_nodes(std::vector<std::int32_t> nodes);
  // rho u^2 / 2 of the 0D vessels at coupling node j (set_coupling_nodes' order; u their
  // flow-weighted mean velocity there, now): what a 1D end's total pressure adds to the
  // node's (static) pressure.
  double dynamic_pressure(std::size_t j) const { return dynamic_[j]; }

  // One step of length dt to t1, in two halves around the 1D vessels' substeps.
  // predict: the pressures at t1 at the coupling nodes with the coupled 1D ends' inflows held
  // at coupled_inflow (per coupling node, in set_coupling_nodes' order: their flows at t0),
  // and each one's response to a change of it: the impedance dp(t1)/dQ_in, the diagonal of
  // the system's inverse there.
  // inflow: the boundary flows into 0D nodes at t1 (inflow_boundaries' order), held_pressure
  // the boundary pressures there (held_boundaries').
  void predict(double dt, std::span<const double> coupled_inflow, std::span<const double> inflow,
               std::span<const double> held_pressure);
  // The tree form's: inlet_flow at the inlet where the inlet vessel is 0D (else unused).
  void predict(double dt, std::span<const double> coupled_inflow, double inlet_flow);
  // The pressure of coupling node j at a fraction s in [0, 1] of the step being taken (linear
  // between the start and the prediction), and its impedance: a coupled end whose inflow
  // departs from the predicted by dQ sees p + s Z dQ (pulse/pulse_solver.cpp).
  double pressure_during_step(std::size_t j, double s) const {
    const double p0 = pressure_[static_cast<std::size_t>(coupling_nodes_[j])];
    return p0 + s * (coupling_predicted_[j] - p0);
  }
  double impedance(std::size_t j) const { return impedance_[j]; }  // at coupling node j
  // What pressure_during_step(j, s) is made of: the pressure at the step's start and the
  // prediction (another rank's coupled end takes them over ranks, and the same arithmetic).
  double start_pressure(std::size_t j) const { return pressure_[static_cast<std::size_t>(coupling_nodes_[j])]; }
  double predicted_pressure(std::size_t j) const { return coupling_predicted_[j]; }
  // predict()'s pressures at t1 at the coupling nodes again, for other held inflows (the same
  // solve, linear in them: their departures from the last held added to its forward half);
  // complete() then takes the departures from these.
  void predict_again(std::span<const double> coupled_inflow);
  // Completes the step with the volumes the 1D ends actually let into each coupling node
  // (coupled_volume, in set_coupling_nodes' order): the pressures at t1 with the departure
  // from the predicted inflows (the same factorisation: its forward half along the coupling
  // nodes' paths, then one backward half for every node), the flows, then the node volumes
  // from them and the pressures from the tube laws. Adds, where boundary_volume is given (per
  // boundary of the run's list), what went in through each boundary at its nodes (flows,
  // pressures, outlets) [m^3].
  void complete(std::span<const double> coupled_volume, std::span<double> boundary_volume = {});
  // Frees what a step works in and leaves nothing in for the next (the edges' linearisation,
  // the system's right-hand side and factorisation: about 40 bytes a vessel) until the next
  // predict() makes it again, linearising every edge anew:
  // for a phase between steps that needs none of it (a run's cycle end). They are first made
  // at the first predict(), not before (a run's start needs none of them either).
  void release_step_arrays();

  // A run over ranks (built with a LumpedCut): the transport of each step's two messages,
  // which predict() and complete() send and wait for (every rank calls both every step). A
  // step that fails on this rank between them (the top's 1D vessels) is abandoned through
  // abandon_step, which tells every rank (the link's down) and throws its refusal.
  void set_link(LumpedLink link) { share_.link = std::move(link); }
  // How a failure of this rank's step is put to every rank (its words there): a lumen
  // closing (CollapsedNode) is named here by a network index alone, which the caller can
  // turn into its own error (PulseSolver: the vessel's id and the time). Unset: as it is.
  void set_failure_words(std::function<std::exception_ptr(std::exception_ptr)> words) {
    share_.failure_words = std::move(words);
  }
  bool over_ranks() const { return share_.on; }
  // A rank's part of a 0D system with loops (built with a LumpedHalo): its system as the
  // link's solver numbers it, and the link, which predict() and complete() call on every rank
  // every step (collectively: a rank with no 0D vessel still calls them).
  bool halo() const { return halo_.on; }
  LumpedHaloSystem halo_system() const;
  void set_halo_link(LumpedHaloLink link) { halo_.link = std::move(link); }
  // Every coupling node of the run (network nodes where 1D ends meet the 0D system), every
  // rank's alike: each step solves K z = e_j for each (every rank its part of z_j), the
  // impedance at its owner, and moves every rank's pressures by its 1D ends' departures from
  // the held inflows (set_coupling_nodes takes this rank's own, none of its ghosts).
  void set_halo_coupling(std::span<const std::int64_t> network_nodes);
  std::size_t halo_couplings() const { return halo_.coupled_node.size(); }
  [[noreturn]] void abandon_step(std::exception_ptr failure);
  // Whether a node or a 0D vessel is held for another rank's sums only (its numbers are that
  // rank's): the top's rank's ghosts, a share's nodes above its roots; in a halo, the nodes
  // other ranks own and the other ranks' vessels.
  bool ghost_node(std::int32_t node) const { return is_ghost_node(static_cast<std::size_t>(node)); }
  bool ghost_vessel(std::int32_t index) const { return is_ghost_edge(first_edge(static_cast<std::size_t>(index))); }
  // The root vessels (their indices here) in the messages' order: on the top's rank its ghosts,
  // every other rank's roots rank after rank; on a share its own (pulse/lumped_cut.hpp). Over
  // ranks a vessel is one section, so its edge is its index.
  const std::vector<std::int32_t>& root_vessels() const { return share_.root_edge; }

  // The state a vessel's samples come from.
  double node_pressure(std::int32_t node) const { return pressure_[static_cast<std::size_t>(node)]; }
  std::int32_t vessel_index(std::size_t vessel) const { return index_of_vessel_[vessel]; }  // -1: 1D
  // A 0D vessel's flow: its sections' mean (one section: its flow).
  double flow(std::int32_t index) const;
  // Its flow at fraction x along it: its section's there; at a node between two sections,
  // their mean.
  double flow_at(std::int32_t index, double x) const;
  // The volume of a 0D vessel that is more than one section, each half at its nodes' pressures
  // as they hold it [m^3].
  double sectioned_volume(std::int32_t index) const;
  // The pressure at fraction x along a 0D vessel: on the steady profile of a compliant tube
  // between its end pressures (the flow is quasi-steady there), not on a line; in sections,
  // the section's there between its nodes.
  double pressure_at(std::int32_t index, double x) const;
  // Every 0D vessel's lumen area, flow and (unless empty) pressure at fraction x along it,
  // into the network's per-vessel arrays (the cycle statistics' samples).
  void sample(double x, std::span<double> area, std::span<double> flow, std::span<double> pressure, int threads) const;
  // Each 0D vessel's flow, and pressure and lumen area at its centre, as sample() gives them,
  // eight vessels to a batch (their pressures, then their lumens: stage by stage, so that the
  // processor overlaps the vessels' chains of dependent operations), passed to f(batch) in
  // parallel over the vessels (f must touch only the batch's vessels' data): what the cycle
  // statistics take of a 0D vessel, in one pass.
  struct CentreBatch {
    static constexpr std::size_t width = 8;
    std::size_t n = 0;                 // vessels in the batch
    std::size_t first = 0;             // the first's index here (its place among vessel_count())
    std::size_t vessel[width] = {};    // their network indices
    double flow[width] = {}, pressure[width] = {}, area[width] = {};
  };
  template <class F>
  void for_each_centre_batch(F&& f, int threads) const {
    const auto vessels = static_cast<std::int64_t>(vessels_.size());
    parallel_blocks(vessels, threads, [&](std::int64_t first, std::int64_t last) {  // f may throw (the caller's)
      CentreBatch batch;
      for (auto e = static_cast<std::size_t>(first); e < static_cast<std::size_t>(last); e += CentreBatch::width) {
        centre_batch(e, std::min(CentreBatch::width, static_cast<std::size_t>(last) - e), batch);
        f(static_cast<const CentreBatch&>(batch));
      }
    });
  }
  // A tapered 0D vessel's volume, half at each of its nodes' pressures as the nodes hold it [m^3].
  double tapered_volume(std::int32_t index) const;
  // The parts of a tapered 0D vessel at its node pressures pa, pb (tests: against quadrature):
  // resistance [Pa s/m^3], inertance [Pa s^2/m^3], and compliance int dA/dp dx at a uniform
  // pressure p [m^3/Pa].
  double tapered_resistance(std::int32_t index, double pa, double pb) const;
  double tapered_inertance(std::int32_t index, double pa, double pb) const;
  double tapered_compliance(std::int32_t index, double p) const;
  // The volume the 0D vessels hold now (what BDF2 conserves: (3 V^n - V^(n-1)) / 2, which
  // is V at a steady state), capacitors not included [m^3].
  double stored_volume() const;
  // The same at one node of a network node (below network_node_count()): a step changes it
  // by exactly dt times the flows into the node at the step's end, plus the coupled ends'
  // volumes: the volume a transport scheme's cell at this node holds (transport/).
  double stored_volume(std::int32_t node) const {
    const auto k = static_cast<std::size_t>(node);
    return node_constant(k) + 0.5 * (3 * volume_[k] - previous_volume_[k]);
  }
  std::size_t network_node_count() const { return network_nodes_; }
  // The system's edges, by node_of's numbering (each 0D vessel's sections in the arrays'
  // order, then the RCR outlets' R1 edges to their capacitor nodes), and the network vessel
  // each belongs to (an R1 edge: the 0D vessel ending at its outlet): what a run over ranks
  // cuts by its partition of the vessels (docs/scaling.md).
  std::span<const std::int32_t> edge_a() const { return a_; }
  std::span<const std::int32_t> edge_b() const { return b_; }
  std::int32_t edge_vessel(std::size_t e) const;
  // A 0D vessel's nodes (its `from`, its `to`).
  std::int32_t from_node(std::int32_t index) const { return a_[first_edge(static_cast<std::size_t>(index))]; }
  std::int32_t to_node(std::int32_t index) const { return b_[first_edge(static_cast<std::size_t>(index) + 1) - 1]; }
  // From now on, each 0D vessel sums the volume it passes from `from` to `to` (dt times its
  // flow at each step's end, the flow BDF2 balances the nodes with; of a vessel in sections,
  // the flow out of `from`) [m^3].
  void track_passed_volumes() { passed_.assign(vessel_edges_, 0.0); }
  void clear_passed_volumes() { std::fill(passed_.begin(), passed_.end(), 0.0); }
  // Each 0D vessel's viscosity is the run's times its factor (per network vessel; the
  // vessel's own hematocrit against the blood's: red-cell transport). Empty: all 1.
  void set_viscosity_factors(std::span<const double> per_vessel);
  void set_viscosity_factor(std::int32_t index, double factor);  // one 0D vessel's
  double passed_volume(std::int32_t index) const { return passed_[first_edge(static_cast<std::size_t>(index))]; }
  // A capacitor's pressure, by the network's outlet index, or NaN if that outlet is not here.
  double capacitor_pressure(std::size_t outlet) const;
  // Compliance of a node at its pressure now [m^3/Pa].
  double compliance(std::int32_t node) const;

  // Shifts every node's pressure by dp of its network node (network_node_dp) or of its
  // outlet (outlet_dp, capacitors), and its volume with it; the multistep history restarts.
  void shift_pressures(std::span<const double> network_node_dp, std::span<const double> outlet_dp);
  // Throws SolutionBreakdown (naming the vessel by its id in vessel_id, per network vessel)
  // where a volume is not finite or a lumen not positive.
  void check(double time, std::span<const std::int64_t> vessel_id) const;

  void save(CheckpointWriter& out) const;
  void restore(CheckpointReader& in);
  // Over ranks (one pi section a vessel): this rank's part of the checkpoint the whole run
  // writes, at the places of the whole's order (pulse/lumped_order.hpp's lumped_places): the
  // places of its own nodes and edges (not its ghosts'), and for each of save()'s six arrays
  // (per node: volume, previous volume, pressure, previous pressure; per edge: flow, previous
  // flow) its values there, in the places' order (share_values: one array at a time).
  static constexpr std::size_t state_arrays = 6;
  struct StateShare {
    std::vector<std::int32_t> node_place, edge_place;
    std::size_t whole_nodes = 0, whole_edges = 0;  // the whole run's
    static bool per_node(std::size_t array) { return array < 4; }
    const std::vector<std::int32_t>& place(std::size_t array) const { return per_node(array) ? node_place : edge_place; }
    std::size_t whole(std::size_t array) const { return per_node(array) ? whole_nodes : whole_edges; }  // an array's length
  };
  StateShare state_share(const LumpedPlaces& places) const;
  std::vector<double> share_values(std::size_t array) const;
  // save()'s section begun: its six arrays follow whole, in the whole's order, each put in
  // turn (CheckpointWriter::put): the one-process bytes.
  static void begin_whole(CheckpointWriter& out);
  // restore() of a rank's share: every node and edge it holds (its ghosts too) from its place
  // in the section the whole run writes.
  void restore_share(CheckpointReader& in, const LumpedPlaces& places);

 private:
  // The arrays are in pulse/lumped_order's subtree order; a checkpoint and the sums over all
  // nodes keep the network's: the node, or edge, at each place of network_lumped_order (then
  // the capacitors, or the R1 edges). O(nodes), built when asked (at cycle ends).
  std::vector<std::int32_t> network_order_nodes() const;
  std::vector<std::int32_t> network_order_edges() const;
  // Per node, and per edge, of this rank's arrays: its place in the whole run's order.
  std::vector<std::int32_t> local_node_places(const LumpedPlaces& places) const;
  std::vector<std::int32_t> local_edge_places(const LumpedPlaces& places) const;

 private:
  // The batch of vessels first .. first + n - 1 (arrays' order) at their centres.
  void centre_batch(std::size_t first, std::size_t n, CentreBatch& batch) const;

  // A vessel's sections are edges first_edge(i) .. first_edge(i + 1) - 1 (one edge each
  // without sections, first_edge_ then empty); the section at fraction x of vessel i, and x
  // within it.
  std::size_t first_edge(std::size_t i) const { return first_edge_.empty() ? i : static_cast<std::size_t>(first_edge_[i]); }
  std::size_t section_at(std::size_t i, double x, double& within) const;
  void start_inner_nodes();  // on the steady profile of their vessels, from the end pressures
  // The pressure at fraction x along edge e on the steady profile between its end pressures.
  double edge_pressure_at(std::size_t e, double x) const;
  bool is_capacitor(std::size_t k) const { return k >= network_nodes_ && k < network_nodes_ + outlet_of_capacitor_.size(); }

  // A node's volume is a quadratic in its pressure (each vessel's L A(p) / 2 is, with the
  // tube law's A = (c + p / beta)^2, and a capacitor's C p is linear): V = a p^2 + b p + c.
  // The state is the excess W = V - c = a p^2 + b p: c drops out of every step (BDF2 is
  // linear in V), and the steps read two coefficients a node, not three.
  double node_excess(std::size_t k, double p) const { return (volume_a_[k] * p + volume_b_[k]) * p; }
  // sqrt(A) of 0D vessel e at pressure p: the tube law's root, linear in p.
  double lumen_root(std::size_t e, double p) const { return edge_root_intercept_[e] + edge_root_slope_[e] * p; }
  // The same at fraction x along it (a tapered vessel's law changes along it).
  double lumen_root(std::size_t e, double p, double x) const {
    if (taper_edge_.empty() || taper_edge_[e] < 0) return lumen_root(e, p);
    return tapered_[static_cast<std::size_t>(taper_edge_[e])].taper.at(x).lumen_root(p);
  }
  // A tapered 0D vessel: its law along it, its volume V(p) = a p^2 + b p + c at a uniform p,
  // and at the rule's points u_i of the rigid taper's resistance (physics/poiseuille.hpp)
  // the lumen's root c_i + d_i p and the reference lumen; unit_resistance is the rigid
  // taper's at unit viscosity.
  struct TaperedEdge {
    VesselTaper taper;
    double volume_a = 0, volume_b = 0, volume_c = 0;
    std::array<double, 8> root_c{}, root_d{}, rigid_area{};
    double unit_resistance = 0;
  };
  std::vector<TaperedEdge> tapered_;
  std::vector<std::int32_t> taper_edge_;  // per 0D vessel edge (empty without tapers)
  bool tapered(std::size_t e) const { return !taper_edge_.empty() && taper_edge_[e] >= 0; }
  static TaperedEdge describe_taper(const VesselTaper& taper, double alpha);
  // Fraction of the rigid taper's resistance built by fraction x of its length.
  double resistance_fraction(std::size_t e, double x) const;
  double node_compliance(std::size_t k, double p) const { return 2 * volume_a_[k] * p + volume_b_[k]; }
  double pressure_from_excess(std::size_t node, double excess) const;
  // The resistance of 0D vessel e between end pressures pa and pb: L over Simpson's mean of
  // its flow capacity G(p) = A^2 / (k mu(A)) (the steady flow is (1/L) times the integral of G
  // from pb to pa), and G at the two ends (the interior profile reads them). Over one common
  // denominator: one division, not four (they were most of a step's evaluation).
  double resistance(std::size_t e, double pa, double pb, double& capacity_a, double& capacity_b) const;
  // The same from the lumen's area at its ends and middle and the viscosity there (length l,
  // the vessel's own viscosity factor f): what resistance() and the batched pass of
  // update_resistances_and_linearise share. Over one common denominator: one division, not
  // four (D stays far inside the doubles' range: ~1e-60 in a 3 um capillary).
  struct SimpsonResistance {
    double resistance, capacity_a, capacity_b;
  };
  static SimpsonResistance simpson_resistance(double k, double l, double f, double aa, double ab, double am,
                                              double mu_a, double mu_b, double mu_m) {
    const double ga = aa * aa * mu_b * mu_m, gb = ab * ab * mu_a * mu_m, gm = am * am * mu_a * mu_b;  // x k mu_a mu_b mu_m
    // With D = product (ga + gb + 4 gm): 1 / product = sum / D and product / sum = product^2 / D.
    const double product = k * mu_a * mu_b * mu_m, sum = ga + gb + 4 * gm;
    const double inverse_d = 1 / (product * sum), inverse = sum * inverse_d;
    // The vessel's own hematocrit scales mu along all of it: R by f, the capacities by 1 / f.
    return {f * 6 * l * product * product * inverse_d, ga * inverse / f, gb * inverse / f};
  }
  // The step's resistance from the last two: extrapolated to the step's end, kept within a
  // factor of two of the last.
  static double extrapolated_resistance(double r, double previous) { return std::clamp(2 * r - previous, 0.5 * r, 2 * r); }
  // BDF2 for an edge: L (3 Q - 4 Q^n + Q^(n-1)) / (2 dt) + R Q = p_a - p_b, so
  // Q = g (p_a - p_b) + h with g = 1 / (R + 3 L / (2 dt)), h = g L (4 Q^n - Q^(n-1)) / (2 dt).
  struct EdgeLine {
    double conductance, history;
  };
  static EdgeLine bdf2_edge(double r, double inertance, double flow, double previous_flow, double dt) {
    const double g = 1 / (r + 1.5 * inertance / dt);
    return {g, g * inertance * (4 * flow - previous_flow) / (2 * dt)};
  }
  // The linearisation of a step: edge conductances and history terms, node shunts and
  // right-hand sides (with the coupled inflows and the inlet's), at the state extrapolated to
  // the step's end (extrapolated) or at the last pass's solution (a Picard pass).
  void linearise(bool extrapolated, std::span<const double> coupled_inflow);
  // Calls f(node, value) for the coupling nodes' values (per coupling node) and the boundary
  // inflows' (scale times each).
  template <class F>
  void for_each_source(std::span<const double> coupled, double scale, F&& f) const {
    for (std::size_t j = 0; j < coupling_nodes_.size() && !coupled.empty(); ++j)
      f(static_cast<std::size_t>(coupling_nodes_[j]), coupled[j]);
    for (std::size_t j = 0; j < inflow_node_.size(); ++j) f(static_cast<std::size_t>(inflow_node_[j]), scale * inflow_[j]);
  }
  // The flow out of the network through held node j in the step just completed.
  double held_outflow(std::size_t j) const { return held_out_[j]; }
  // The constructor's steps: the boundary conditions' rows at 0D nodes (shunts, currents,
  // held nodes, RCR capacitor nodes; pulse/lumped_boundary_rows.cpp), and the nodal system
  // with the per-node and per-edge arrays and each node's incident edges.
  void add_boundary_rows(const Network& net, std::span<const TubeLaw> laws, const ViscosityTable& viscosity);
  void allocate_system();
  void allocate_step_arrays();  // where released (or never made)
  void predict_coupling_pressures();  // coupling_predicted_ from the forward half rhs_
  void hold_coupling_pressures();     // coupling_predicted_ at the pressures now (no step taken)
  void restart_history();
  void update_dynamic_pressures();
  void update_resistances();  // after the pressures changed: capacities at the ends, R
  // The same after a step, and the next step's edges (linearise's extrapolated pass) for a
  // step of dt in the same pass; linearised_dt_ = dt says they are (0: not).
  void update_resistances_and_linearise(double dt);
  void linearise_edge(std::size_t e, double pa, double pb, double r, double dt);  // with its resistance r
  double linearised_dt_ = 0;

  std::size_t nodes_ = 0, network_nodes_ = 0;  // network nodes first, then capacitor nodes, then inner nodes
  std::vector<std::int32_t> node_of_;          // per network node
  std::vector<std::int32_t> index_of_vessel_;  // per network vessel
  std::vector<std::int32_t> vessels_;          // per 0D vessel: its network index
  std::vector<std::int32_t> first_edge_;       // per 0D vessel and one more (empty: one section each)
  std::size_t vessel_edges_ = 0;               // the 0D vessels' edges (their sections)
  // Boundary flows (currents into their nodes) and held pressures: node, place in
  // the run's list; a held node's conductance scale (its vessel's at rest).
  std::vector<std::int32_t> inflow_node_, inflow_boundary_, held_node_, held_boundary_;
  std::vector<std::int32_t> held_;  // per node: 1 + its place in held_node_, or 0 (empty: none held)
  std::vector<double> inflow_, held_reference_conductance_, held_out_;
  // The outlets by their place in the run's list: a shunt at a node, or an RCR's R1 edge.
  struct OutletNode {
    std::int32_t boundary, node;
  };
  struct OutletEdge {
    std::int32_t boundary, r1_edge;
  };
  std::vector<OutletNode> outlet_boundary_;
  std::vector<OutletEdge> rcr_outlet_boundary_;

  // Edges: the 0D vessels' sections (first), then the R1 of every RCR outlet on them.
  std::vector<std::int32_t> a_, b_;
  std::vector<double> edge_length_, edge_root_intercept_, edge_root_slope_;  // sections: L / n, s(p) = c + p / beta
  std::vector<double> edge_fixed_resistance_;  // R1 edges
  double density_ = 0, friction_k_ = 0;
  const ViscosityTable* viscosity_ = nullptr;
  std::vector<std::int32_t> capacitor_vessel_edge_;  // per R1 edge: the 0D vessel ending at it
  std::vector<int> capacitor_edge_sign_;             // and +1 if it ends there at `to`, -1 at `from`

  // Node volume V(p) = a p^2 + b p + c (half of each 0D vessel, capacitors).
  // In float: the compliances shape the pulse, not the mean state, and move the results by
  // less than 1e-6 of themselves (bench/README.md, "Coefficients in float").
  std::vector<float> volume_a_, volume_b_;
  double node_constant(std::size_t k) const;  // c, from the node's edges: only to report V
  std::int32_t vessel_at_node(std::size_t k) const;  // a network vessel ending there (its R1's, at a capacitor)
  // Shunts to ground: conductance and the pressure behind it (outlets, R2). Where every
  // shunt has one pressure behind it (a tree's outlets drain to one venous pressure) and no
  // node is held, shunt_pressure_ is empty and that pressure is uniform_shunt_pressure_ (not
  // negative, so that a node without a shunt has the same +0 current as with a 0 there).
  std::vector<double> shunt_, shunt_pressure_;
  double uniform_shunt_pressure_ = 0;
  double shunt_pressure(std::size_t k) const {
    return shunt_pressure_.empty() ? (shunt_[k] != 0 ? uniform_shunt_pressure_ : 0.0) : shunt_pressure_[k];
  }
  double shunt_current(std::size_t k) const {
    return shunt_pressure_.empty() ? shunt_[k] * uniform_shunt_pressure_ : shunt_[k] * shunt_pressure_[k];
  }
  void share_shunt_pressure();  // empties shunt_pressure_ where it can
  std::vector<std::int32_t> outlet_of_capacitor_;  // per capacitor node
  std::vector<std::int32_t> capacitor_of_outlet_;  // per run outlet, -1 if none here

  NodalSystem system_;
  // State: node volumes (W, above c) and pressures, edge flows, and the last step's (BDF2 history and
  // the extrapolation).
  std::vector<double> volume_, previous_volume_, pressure_, previous_pressure_, flow_, previous_flow_;
  // The step being taken: the edges' conductances and history terms of the last
  // linearisation (Q = g (p_a - p_b) + f), and the nodes' right-hand side (their shunts go
  // straight into the system's workspace). The solve works in place: rhs_ holds the forward
  // half's y from predict() on, and the pressures at t1 once complete() (or a Picard pass)
  // has taken the backward half.
  std::vector<double> conductance_, history_, rhs_;
  std::vector<double> passed_;  // per 0D vessel edge, where tracked (track_passed_volumes)
  std::vector<double> viscosity_factor_;  // per 0D vessel edge (empty: 1)
  void refresh_resistance(std::size_t e);  // after its factor changed: what restore() computes
  std::vector<std::int32_t> coupling_nodes_;
  std::vector<std::int64_t> coupling_edge_offset_;  // per coupling node: its 0D vessels
  std::vector<std::int32_t> coupling_edge_;
  std::vector<double> dynamic_;  // per coupling node
  // Each 0D vessel edge's pressure at its centre (what the statistics sample every step; other
  // points of the profile take the resistance's flow capacities again), and its resistance
  // now: the viscosity is most of the cost, three evaluations a vessel and step. The next
  // step extrapolates from it and the last step's, which the step's completion has at hand
  // as it replaces it; a step linearised anew (after a cycle end) computes the last one again
  // from the previous pressures, the same bits (it is a function of them).
  std::vector<double> centre_pressure_, resistance_;
  // The pressure at the centre of edge e on its steady profile, from its end pressures and
  // flow capacities there; and the resistance and centre pressure of edge e at the pressures now.
  double centre_pressure(std::size_t e, double pa, double pb, double ga, double gb) const;
  void update_resistance(std::size_t e);
  std::vector<double> impedance_;     // per coupling node: Z
  std::vector<double> held_inflow_;   // per coupling node: the inflows predicted with
  std::vector<double> coupling_scratch_;  // per coupling node
  std::vector<double> coupling_predicted_;  // per coupling node: its pressure at t1, predicted (then solved)
  // Each node's edges, in increasing order (e where the edge leaves it, ~e where it enters):
  // the sums into a node are gathers, in parallel and in one order whatever the threads.
  // Where every edge e leads to node e + 1 from a lower node (a tree's vessels in the order
  // of their distal nodes, as the subtree order numbers them: own_edge_), that edge, node
  // e + 1's first, is not listed but read from b_.
  std::vector<std::int32_t> incident_offset_, incident_edge_;
  bool own_edge_ = false;
  template <class F>
  void for_each_incident(std::size_t k, F&& f) const {
    if (own_edge_ && k >= 1 && k <= a_.size()) {
      const auto e = static_cast<std::int32_t>(k - 1);
      f(b_[k - 1] == static_cast<std::int32_t>(k) ? ~e : e);
    }
    for (auto j = incident_offset_[k]; j < incident_offset_[k + 1]; ++j) f(incident_edge_[static_cast<std::size_t>(j)]);
  }
  static constexpr std::size_t block = 4096;  // nodes a task of the completion; values a piece of a checkpoint
  // A rank's part of a run over ranks (pulse/lumped_cut.hpp; `on` false where the run is whole).
  struct Share {
    bool on = false, top = true;
    std::vector<std::int32_t> root_edge;    // the messages' edges in their order: a share's into the top, the top's ghosts
    std::vector<unsigned char> ghost_node;  // per node (empty: none)
    std::vector<unsigned char> ghost_edge;  // per edge: the top's ghosts (empty: none)
    std::vector<double> root_row;           // the top's: per ghost edge, its message; a share's: per root, u's pressure
    std::vector<std::int32_t> waiting_node;  // the top's nodes above the shares' roots (their rows need the messages)
    // The step's messages: the top's still to take in; the potentials and the pressures gone
    // down (a share: taken in).
    bool awaiting_roots = false, potentials_down = false, pressures_down = false;
    LumpedLink link;
    std::function<std::exception_ptr(std::exception_ptr)> failure_words;
  } share_;
  // ghost_node: 1 a ghost, 2 a node of the top's that waits for the shares' roots.
  bool is_ghost_node(std::size_t k) const { return !share_.ghost_node.empty() && share_.ghost_node[k] == 1; }
  bool waits_for_roots(std::size_t k) const { return !share_.ghost_node.empty() && share_.ghost_node[k] == 2; }
  bool is_ghost_edge(std::size_t e) const { return !share_.ghost_edge.empty() && share_.ghost_edge[e]; }
  void hold_cut(const LumpedCut& cut);  // the constructor's: ghosts and root edges
  // A rank's part of a 0D system with loops: its ghost nodes (share_.ghost_node 1) and halo
  // vessels (share_.ghost_edge) are marked as a share's; every key's rank, the shunts of its
  // rows (the system is the link's: system_ holds none), the link.
  struct Halo {
    bool on = false;
    std::vector<std::int32_t> key_rank;
    std::vector<double> shunt;
    LumpedHaloLink link;
    // The run's coupling nodes: per one, its node here (-1: none) and its slot among this
    // rank's own (-1: another rank's); z_j = K^-1 e_j, node after node (one column a
    // coupling node); the departures of the step.
    std::vector<std::int32_t> coupled_node, coupled_slot;
    std::vector<double> response, departure;
  } halo_;
  void hold_halo(const LumpedHalo& halo);  // the constructor's
  void predict_on_halo(double dt, std::span<const double> coupled_inflow, std::span<const double> inflow,
                       std::span<const double> held_pressure);
  // rhs_ (the pressures at t1) moved by each coupling node's departure from its held inflow:
  // per own coupling slot, its departure (summed over the ranks first).
  void add_halo_departures(const std::function<double(std::size_t slot)>& departure);
  // A root vessel's (edge e's) ends: u, the top's node above it, and r, the share's root below
  // it. Every node hangs from one before it in the whole run's order, and so in a rank's.
  std::size_t root_upper(std::size_t e) const { return static_cast<std::size_t>(std::min(a_[e], b_[e])); }
  std::size_t root_lower(std::size_t e) const { return static_cast<std::size_t>(std::max(a_[e], b_[e])); }
  // A step's messages (pulse/lumped_exchange.cpp): a share's roots up after its forward half
  // (or its failure); the top's taken in before its linearisation (false: a rank failed);
  // the potentials at the roots' ends down after the top's backward half, a share's taken in
  // before its own; u's pressures down once the top has completed its nodes, a share's taken
  // in after completing its own (before its linearisation, which reads them).
  void send_roots(std::exception_ptr failure);
  void take_roots();
  void answer_potentials();
  void take_potentials();
  void answer_pressures();
  void take_pressures();
  // One message down (`sent` marks it), the refusal of a failed rank thrown on every rank.
  std::vector<double> exchange_down(std::span<const double> answers, std::size_t per_root, bool& sent);
  std::exception_ptr in_words(std::exception_ptr failure) const {
    return share_.failure_words ? share_.failure_words(failure) : failure;
  }
  // The step on this rank's vessels, between the messages (and the whole run's step).
  void predict_step(double dt, std::span<const double> coupled_inflow, std::span<const double> inflow,
                    std::span<const double> held_pressure);
  void complete_step(std::span<const double> coupled_volume, std::span<double> boundary_volume);
  double dt_ = 0;
  int passes_ = 1, threads_ = 1;
};

}  // namespace hemotree
