// The spectral/hp discontinuous Galerkin solver of pulsatile flow in a compliant network
// (the paper's "Numerical approximation method"): modal Legendre elements in every 1D vessel,
// upwind (Roe) fluxes between elements, junctions and boundaries solved through the
// characteristics, second-order Adams-Bashforth (or classical Runge-Kutta) in time.
// The state of all elements lives in flat matrices (one row per element), and each stage
// of the right-hand side acts on all of them at once.
// Vessels far shorter than the pulse's wavelength may be 0D instead (pulse/lumped_vessels,
// implicit): then a step is one 0D step with several explicit 1D substeps inside it.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "formats/network.hpp"
#include "harmonic/linear_periodic.hpp"
#include "physics/viscosity_table.hpp"
#include "pulse/degree_choice.hpp"
#include "pulse/legendre_basis.hpp"
#include "pulse/lumped_vessels.hpp"
#include "pulse/network_boundaries.hpp"
#include "pulse/one_d_cut.hpp"
#include "formats/checkpoint_file.hpp"
#include "steady/steady_flow.hpp"
#include "pulse/time_scheme.hpp"
#include "physics/vessel_taper.hpp"

namespace hemotree {

struct TreePotentials;  // steady/loaded_tree.hpp: the compliance balance's moves

// Which vessels are 1D (DG) and which 0D (lumped): all of one kind, or chosen per vessel.
enum class ModelChoice { automatic, one_d, zero_d };

// The state a run starts from: the reference pressures at rest; the steady solution of the
// mean inflow; or the linear periodic state about it (harmonic/linear_periodic.hpp) at t = 0.
// The last two fall back to rest where the network has no steady state (reflection outlets).
enum class StartChoice { rest, steady, periodic };

struct SolverOptions {
  static constexpr int automatic = -1;
  ModelChoice model = ModelChoice::one_d;  // the DG solver; hemosolve defaults to automatic
  // automatic: a vessel is 0D when a wave crosses it in less than this fraction of the
  // period (L / c0 < lumped_transit T) and the pressure diffuses along it fast enough
  // (w R C < lumped_rc at the pulse's fundamental), unless it ends in a reflection outlet.
  double lumped_transit = 3e-3;
  double lumped_rc = 1.6;
  // The most pi sections a 0D vessel takes: one whose w R C exceeds lumped_rc (a long
  // capillary: the pressure diffuses along it) is n = floor(sqrt(w R C / lumped_rc)) + 1
  // sections, each below lumped_rc, where n is at most this; else it is 1D. 1: one section
  // each, every such vessel 1D.
  int lumped_sections = 8;
  // The 0D step, as a fraction of the period (at most); 0: a thousandth of the period for
  // each coupling pass.
  double lumped_step = 0;
  // How many times a 0D step's 1D substeps are taken, each later pass with the 0D vessels'
  // prediction from the inflows the one before let through (docs/solver.md §10); automatic:
  // the number that costs least per cycle (pulse/step_cost.hpp), at most four.
  int coupling_passes = automatic;
  int lumped_passes = 1;      // linear solves per 0D step (1: at the extrapolated state)
  int degree = automatic;   // p in every vessel, or chosen per vessel by degree_rule
  DegreeRule degree_rule;
  int elements = 1;         // per vessel
  int quadrature_points = 0;  // 0: the default over-integration
  TimeScheme scheme = TimeScheme::exponential_ab2;
  double dt = 0;            // 0: chosen from the stability limits
  double cfl = 0.9;         // fraction of the wave-speed (Courant) limit of the degree and scheme
  double friction_safety = 0.5;  // safety on the friction-stiffness limit
  double external_pressure = 10 * 133.322;  // p_ext for the wall laws [Pa]
  double thick_wall_ratio = 0.1;
  StartChoice start = StartChoice::periodic;
  int periodic_harmonics = 10;  // the inflow's harmonics the linear periodic state takes (start and --linear)
  int rheology_override = -1;  // -1: the file's; else static_cast<int>(Rheology)
  // Threads over elements. One by default: a step has several parallel sections, and a
  // thread that the system deschedules stalls every barrier (measured on the shared 2-core
  // machine: 1001 vessels ran 35x slower with 2 threads while another job ran).
  int threads = 1;

  // --model automatic's rule: a vessel the pulse crosses in phase, its wave transit L / c0
  // and its w R C (at the fundamental) below their bounds, is 0D.
  bool moves_in_phase(double transit, double omega_rc, double period) const {
    return transit < lumped_transit * period && omega_rc < lumped_rc;
  }
  // And the pi sections it takes: those that bring each one's w R C (which falls as 1 / n^2)
  // below lumped_rc, where its transit is below lumped_transit; 0: it is 1D.
  int lumped_sections_of(double transit, double omega_rc, double period) const {
    if (!(transit < lumped_transit * period)) return 0;
    if (omega_rc < lumped_rc) return 1;
    const double n = std::floor(std::sqrt(omega_rc / lumped_rc)) + 1;
    return n <= lumped_sections ? static_cast<int>(n) : 0;
  }
};

// The discrete state: modal coefficients of A and Q per element, the pressures of the RCR
// outlets' capacitors, and the volumes through the boundaries at 1D ends, integrated by the
// same scheme as the areas, so that in - out - (change in the vessels' volume) is the scheme's
// own mass balance (round-off and the junctions' Newton tolerance).
struct PulseState {
  Eigen::MatrixXd area, flow;  // elements x modes
  Eigen::VectorXd capacitor;   // one per RCR outlet [Pa]
  Eigen::VectorXd coupled;     // per 1D end at a 0D node: the volume it let into the node [m^3]
  // Per boundary at a 1D end (NetworkBoundaries::one_d_boundary): the volume in through it
  // [m^3]; PulseSolver::boundary_volume gives every boundary's.
  Eigen::VectorXd boundary;
  // Per element, where tracked (track_face_volumes; else empty): the volume through its left
  // face along the vessel [m^3]. Its area's mode 0 changes by exactly the difference of two
  // of these, which is what a transport scheme's cells need (transport/).
  Eigen::VectorXd faces;

  void set_zero_like(const PulseState& other);
  void add_scaled(double factor, const PulseState& other);  // this += factor * other
};

// A run over ranks (docs/scaling.md, "The pulsatile run over ranks"), in one of two ways the
// caller's partition chooses (vessel_ranks: per vessel its rank, given which are 0D and what
// each costs a step):
//  - a tree mostly 0D: this rank's whole subtrees of 0D vessels and, on the top's rank, every
//    1D vessel and the 0D vessels above them (pulse/lumped_cut.hpp); each step's two messages
//    carried by link. One pi section a 0D vessel (SolverOptions::lumped_sections 1);
//  - the 1D vessels spread over the ranks (one_d_spread; pulse/one_d_cut.hpp), the 0D vessels
//    meeting at a node on one rank, so that a rank's 0D system is its own; the traces at
//    junctions across the cut exchanged at every evaluation, and the coupled ends' inflows,
//    nodes and volumes at every step where a 1D end's 0D node is another rank's (exchange);
//    or the 0D vessels spread too (zero_d_spread: a capillary bed that whole would leave a
//    rank empty): each rank its own and a halo of the others' at its nodes
//    (pulse/lumped_halo.hpp), each step solved over every rank's rows (halo_link).
struct VesselRanks {
  std::vector<std::int32_t> rank;
  bool one_d_spread = false, zero_d_spread = false;
};
struct PulseRanks {
  int ranks = 1, rank = 0, top_rank = 0;
  std::function<VesselRanks(const std::vector<bool>& zero_d, std::span<const double> step_cost)> vessel_ranks;
  // Told the cut once it is made (the messages' sizes: LumpedCut::roots), before any step.
  std::function<void(const LumpedCut& cut)> cut_made;
  LumpedLink link;
  // The 0D vessels spread (zero_d_spread): the link of a rank's halo, made for its system.
  // Collective.
  std::function<LumpedHaloLink(const LumpedHaloSystem& system)> halo_link;
  // The 1D vessels spread: numbers out to each neighbouring rank and in from it (send[i] to
  // neighbours[i], receive[i] from it, each of the size both sides know). Collective among
  // the neighbours.
  std::function<void(std::span<const int> neighbours, const std::vector<std::vector<double>>& send,
                     std::vector<std::vector<double>>& receive)>
      exchange;
  // The least of every rank's key (a failure's place in the run's order; none: the largest
  // int64). Collective.
  std::function<std::int64_t(std::int64_t key)> least_key;
  // values: one per item (vessel, outlet), this rank's right where `mine` is set (each item
  // is one rank's); after the call, every rank's values are every item's holder's. Collective.
  std::function<void(std::vector<double>& values, const std::vector<unsigned char>& mine)> make_whole;
  // The same on the top's rank alone (the others' values left as they are): a checkpoint's.
  // (Over MPI the top is rank 0, which writes the results: solver/pulse_ranks_mpi.hpp.)
  std::function<void(std::vector<double>& values, const std::vector<unsigned char>& mine)> lead_whole;
  // The same from this rank's own items alone: values[i] at item place[i] of count; returns
  // on the lead every item's (0 where no rank places one), empty elsewhere. Collective.
  std::function<std::vector<double>(std::span<const double> values, std::span<const std::int32_t> place, std::size_t count)>
      lead_places;
  // The lead's values (any length) on every rank: what the lead alone computes from the whole,
  // e.g. the compliance balance's moves. Collective.
  std::function<void(std::vector<double>& values)> from_lead;
  int lead_rank = 0;  // where lead_whole gathers and from_lead sends from (the results' writer)
};

class PulseSolver {
 public:
  // ranks: where given, this rank's part of a run over ranks (every rank builds the whole
  // network's laws, models, step and start alike; it steps its own vessels).
  PulseSolver(const Network& net, const SolverOptions& options, const PulseRanks* ranks = nullptr);

  void step();  // advances one time step (one 0D step, with its 1D substeps, where there are 0D vessels)
  // The same; on a share of a run over ranks, while_waiting is called once its roots are sent,
  // while the top's rank takes its 1D substeps: the share's state is still the step's start
  // (t = time()), so that work reading it (the last step's statistics) fills the wait.
  void step(const std::function<void()>& while_waiting);
  double time() const { return time_; }
  double dt() const { return dt_; }
  // Replaces the chosen step (e.g. by one that divides the period); the reason stays.
  void set_time_step(double dt);
  // The 1D substeps of a step (1 without 0D vessels), and their length.
  int substeps() const { return substeps_; }
  int coupling_passes() const { return coupling_passes_; }  // 1 without 0D vessels or 1D ends on them
  // Replaces the chosen passes (at least 1): a settling cycle takes one (solver/settling_cycle.hpp).
  void set_coupling_passes(int passes) { coupling_passes_ = passes < 1 ? 1 : passes; }
  double substep() const { return dt_ / substeps_; }
  bool is_lumped(std::size_t vessel) const { return zero_d_[vessel]; }
  // The whole run's 0D vessels (over ranks, every rank's: what the step is chosen by, alike
  // on every rank).
  std::size_t lumped_vessels_in_run() const { return static_cast<std::size_t>(std::count(zero_d_.begin(), zero_d_.end(), true)); }
  // The 0D vessels in more than one pi section (their inner nodes are no network node's).
  std::size_t sectioned_count() const { return sectioned_count_; }
  std::size_t lumped_count() const {
    return lumped_count_after_release_ ? *lumped_count_after_release_ : lumped_.vessel_count();
  }
  // What sets the step; a setting it names is a placeholder (core/setting_error.hpp), for the
  // caller to word: in_words(dt_reason(), words).
  const std::string& dt_reason() const { return dt_reason_; }
  // The largest step the run takes without --force, whatever --dt asked for, and what sets
  // it: the scheme's stability limit (cfl times it) with 1D vessels alone; with 0D vessels the
  // 0D step's accuracy limit (--lumped-step of the period; the 1D substeps keep their own).
  double stable_dt() const { return stable_dt_; }
  const std::string& stable_dt_reason() const { return stable_dt_reason_; }
  std::size_t steps() const { return steps_; }
  // Sets the clock back to t = 0 and the step count to 0, the state as it is: after a cycle
  // that only settles the state (solver/settling_cycle.hpp), whose boundaries are periodic.
  void restart_clock() {
    time_ = 0;
    steps_ = 0;
  }
  // Starts again, at t = 0, from the state of another solver of this network with the same
  // models that differs in its discretisation (degrees, step): every 1D vessel's area and flow
  // projected onto this one's modes, the 0D vessels' and the outlets' capacitors' state as
  // they are (a settling cycle at a low degree, solver/settling_cycle.hpp). std::invalid_argument
  // for a solver of another network or other models.
  void start_from(const PulseSolver& other);

  // The solution at fraction x in [0, 1] along a vessel (index).
  double area_at(std::size_t vessel, double x) const;
  double flow_at(std::size_t vessel, double x) const;
  double pressure_at(std::size_t vessel, double x) const;
  // Mean flow over the vessel (its mode-0 coefficients, averaged over its elements).
  double mean_flow(std::size_t vessel) const;
  double viscosity_at(std::size_t vessel, double x) const;  // [Pa s]
  double viscosity(double area) const { return viscosity_(area); }  // [Pa s] at a lumen area
  // The same in a vessel: times its factor (set_viscosity_factors).
  double viscosity(std::size_t vessel, double area) const {
    return viscosity_factor_.empty() ? viscosity_(area) : viscosity_factor_[vessel] * viscosity_(area);
  }
  // Each vessel's viscosity is the run's times its factor from now on: its own hematocrit's
  // Pries viscosity over the blood's (red-cell transport). Empty: all 1.
  void set_viscosity_factors(std::span<const double> per_vessel);
  // The same for one vessel (the rest keep theirs): O(1), as a transport updates them.
  void set_viscosity_factor(std::size_t vessel, double factor);
  const std::vector<double>& viscosity_factors() const { return viscosity_factor_; }
  // Area, flow and pressure of every vessel at the same fraction x along each, in one pass;
  // pressure may be null.
  void sample_all(double x, std::vector<double>& area, std::vector<double>& flow,
                  std::vector<double>* pressure = nullptr) const;
  // The same for the 1D vessels alone, in one_d_vessels()' order (spans of that size;
  // pressure may be empty): the cycle statistics read the 0D vessels whole from lumped().
  void sample_one_d(double x, std::span<double> area, std::span<double> flow, std::span<double> pressure = {}) const;
  const LumpedVessels& lumped() const { return lumped_; }
  // After the last step, once the state is saved and sampled: the 0D vessels' arrays freed
  // (330 B a vessel) before the report, which reads the vessels' models, laws and degrees
  // only. The solver takes no step after it; lumped_count() keeps its value.
  void release_lumped_state() {
    if (!lumped_count_after_release_) lumped_count_after_release_ = lumped_.vessel_count();
    lumped_ = LumpedVessels();
  }
  // Between steps: the 0D step's working arrays freed until the next step makes them again
  // (LumpedVessels::release_step_arrays; the same numbers), for a phase that takes no step.
  void release_step_arrays() { lumped_.release_step_arrays(); }
  // The run's boundary conditions (formats/run_boundaries.hpp), and per
  // boundary whether its flow counts as "in"; the period of its waveforms.
  const RunBoundaries& boundary_list() const { return boundaries_.list; }
  const std::vector<unsigned char>& boundary_entering() const { return boundaries_.entering; }
  double period() const { return period_; }
  // From now on the state sums the volume through every element's left face (state().faces)
  // and every 0D vessel the volume it passes (lumped().passed_volume): a transport's fluxes.
  void track_face_volumes();
  // Starts both sums again from zero (a transport takes them every few steps: small sums
  // keep their digits over a long run).
  void clear_face_volumes() {
    state_.faces.setZero();
    lumped_.clear_passed_volumes();
  }
  const NetworkBoundaries& network_boundaries() const { return boundaries_; }
  std::int32_t first_element(std::size_t vessel) const {  // -1: a 0D vessel
    if (zero_d_[vessel]) return -1;
    const auto v = static_cast<std::int32_t>(vessel);
    return std::lower_bound(first_elements_.begin(), first_elements_.end(), std::pair{v, std::int32_t{-1}})->second;
  }
  int elements_per_vessel() const { return elements_per_vessel_; }
  double element_half_length(std::size_t element) const { return half_length_(static_cast<Eigen::Index>(element)); }
  // The 1D vessels (indices) this rank steps (alone: every one), in the order of their elements.
  const std::vector<std::int32_t>& one_d_vessels() const { return one_d_vessels_; }
  int threads() const { return threads_; }
  // Whether this rank takes the 1D substeps (alone, always; over ranks, the top's rank, or
  // every rank where the 1D vessels are spread), and steps a vessel (over ranks: its own, not
  // the top's ghosts).
  bool holds_one_d() const { return one_d_here_; }
  bool one_d_spread() const { return one_d_cut_.has_value(); }
  bool over_ranks() const { return lumped_.over_ranks() || one_d_spread(); }
  bool steps_vessel(std::size_t vessel) const { return steps_vessel_.empty() || steps_vessel_[vessel]; }
  // Whether this rank holds the whole run's numbers (alone, always; over ranks the lead, which
  // gathers and writes them): the compliance balance is solved there.
  bool leads() const { return !from_lead_ || rank_ == lead_rank_; }
  // With the 1D vessels spread: every vessel's rank, and this rank (what a transport over the
  // same cut needs: solver/flow_transport_spread.cpp). Empty otherwise.
  std::span<const std::int32_t> vessel_ranks() const { return vessel_rank_; }
  // Per network node the rank that owns it among the 0D vessels' nodes (-1: none's): its
  // system's rank, or in a halo its first vessel's (pulse/lumped_halo.hpp). Empty likewise.
  std::span<const std::int32_t> lumped_node_ranks() const { return lumped_node_rank_; }
  int rank() const { return rank_; }
  int rank_count() const { return rank_count_; }

  // A vessel's tube law: at its `from` end (the whole vessel's unless it tapers), at one of
  // its ends, and at fraction x along it.
  TubeLaw law(std::size_t vessel) const {
    return laws_.empty() ? TubeLaw{law_beta_[vessel], law_area_[vessel], law_pressure_[vessel], blood_.density, blood_.momentum_alpha()}
                         : laws_[vessel];
  }
  const TubeLaw& end_law(std::size_t vessel, bool distal) const {  // a 1D vessel's
    return distal && !taper_of_.empty() && taper_of_[vessel] >= 0 ? distal_laws_[static_cast<std::size_t>(taper_of_[vessel])]
                                                                  : element_law_[static_cast<std::size_t>(first_element(vessel))];
  }
  TubeLaw law_at(std::size_t vessel, double x) const;
  bool is_tapered(std::size_t vessel) const { return !taper_of_.empty() && taper_of_[vessel] >= 0; }
  const Blood& blood() const { return blood_; }
  int degree(std::size_t vessel) const { return vessel_degree_[vessel]; }  // -1: 0D
  int max_degree() const { return static_cast<int>(bases_.size()) - 1; }
  std::size_t element_count() const { return static_cast<std::size_t>(state_.area.rows()); }
  const PulseState& state() const { return state_; }
  // The volume in through boundary b (the run's order: boundary_list()) since the start
  // [m^3], and every boundary's.
  double boundary_volume(std::size_t b) const {
    const std::int32_t slot = boundary_slot_[b];
    return slot >= 0 ? state_.boundary(slot) : lumped_boundary_volume_[b];
  }
  Eigen::VectorXd boundary_volumes() const;
  // What came in through the boundaries that count as entering (boundary_entering()) and went
  // out through the others since the start [m^3]: every boundary's volume, in the run's order.
  Eigen::Vector2d exchanged_volumes() const;
  // The boundaries this rank holds (over ranks: its 0D vessels' and, on the top's rank, the
  // 1D ends'; alone: every one at a vessel), increasing.
  std::vector<std::int32_t> held_boundaries() const;
  // network_volume()'s terms after the 0D vessels' stored volume: 1D vessel v's elements'
  // volumes, in its order.
  std::vector<double> one_d_volumes(std::size_t vessel) const;
  // Throws SolutionBreakdown when A <= 0 or a value is not finite.
  void check_solution() const;

  // Whether the run started from the steady solution; if it was asked to and could not,
  // why (the steady solver's message).
  // Whether the run started from the steady solution (alone, or with the periodic state
  // about it), and which start it took.
  bool started_from_steady() const { return started_from_steady_; }
  StartChoice started_from() const { return started_from_; }
  const std::string& steady_refusal() const { return steady_refusal_; }
  // Why a periodic start fell back to the steady one ("" where it did not).
  const std::string& periodic_refusal() const { return periodic_refusal_; }
  // Lowest and highest steady node pressure [Pa] (NaN without a steady solution), and the
  // index of the vessel entering the node of the highest.
  double steady_pressure_min() const { return steady_pressure_min_; }
  double steady_pressure_max() const { return steady_pressure_max_; }
  std::size_t steady_pressure_max_vessel() const { return steady_pressure_max_vessel_; }
  // Blood volume in all vessels now [m^3] (mode 0 of the areas).
  double network_volume() const;

  // The whole evolving state (solution, multistep history, junction guesses, compliance
  // balance marks, time), written and read back bit for bit: a run resumed from it goes on
  // exactly as the uninterrupted run would. The rest is rebuilt from the network and options.
  void save(CheckpointWriter& out) const;
  void restore(CheckpointReader& in);
  // Over ranks: the whole run's checkpoint (save()'s bytes, one pi section a vessel), written to
  // `out` on the top's rank (the lead: PulseRanks), null elsewhere. Collective. restore() reads
  // it on every rank, for any rank count, one included.
  void save_over_ranks(CheckpointWriter* out) const;

  // To be called at the start of the run and at the end of each cycle (of length period).
  // The slowest part of the approach to the periodic state is the filling of the network's
  // compliances (vessels and RCR capacitors) through its resistances. Over a cycle each
  // changes its volume at a mean rate I; linearised about the steady network (an RC tree
  // with the vessels' compliances at their nodes), the pressure shifts that put it at its
  // limit follow from two O(vessels) solves of that tree (docs/solver.md §6).
  // Every vessel's area and every capacitor moves by them. At the periodic state the rates
  // vanish and nothing moves. Returns the vessels moved (0 without a steady solution).
  // mean_pressure (per vessel, the last cycle's), where given (not empty), is the state the
  // network's conductances are taken at; else the steady solution's. It is freed once they
  // are (the balance's largest moment comes later).
  std::size_t balance_compliances(double period, std::vector<double> mean_pressure = {});

 private:
  // The DG rate dU/dt of the 1D vessels at time t (pulse/dg_rate.cpp), and its steps in order.
  void evaluate(double t, const PulseState& s, PulseState& rate);
  // (F, dphi/dx), S, traces; returns the first element whose area is not positive and finite, or -1.
  Eigen::Index volume_terms(const PulseState& s, PulseState& rate);
  // Returns the first element whose area is not positive and finite, or -1.
  Eigen::Index element_terms(const PulseState& s, PulseState& rate, const ModalBasis& basis, Eigen::Index first,
                             Eigen::Index count);
  void interior_face_fluxes();                          // upwind F* between a vessel's elements
  void prescribed_end_fluxes(double t);                 // F(U*) at given flows and pressures
  void coupled_end_fluxes(double t, PulseState& rate);  // at nodes of 0D vessels; their inflows
  void outlet_end_fluxes(const PulseState& s, PulseState& rate);  // R, RCR (dp_c/dt), reflection
  void boundary_exchange(PulseState& rate) const;       // volumes in and out through the boundaries
  std::int64_t junction_fluxes();                       // each junction's Riemann problem; the first that fails, or -1
  void exchange_traces();  // the 1D vessels spread: the traces at junctions across the cut (one_d_over_ranks.cpp)
  void lift_to_rate(PulseState& rate) const;            // surface term, 1/J, source's projection
  void trace(const VesselEnd& end, double& a, double& q) const;  // the inner trace at an end
  void set_end_flux(const VesselEnd& end, const EndState& u);    // F(U*) there; U* kept
  // The step from the stability limits, and the schemes (pulse_time_stepping.cpp).
  void choose_time_step(const SolverOptions& options);   // the step, its limit and their reasons
  void choose_stable_step(const SolverOptions& options);  // the 1D vessels' stability limit
  void step_exponential(double h);  // ETD2 in the friction, AB2 in the rest
  void step_1d(double h);  // one step of the 1D vessels, time_ from t to t + h
  void step_coupled(const std::function<void()>& while_waiting);  // a 0D step around its 1D substeps
  void take_coupled_substeps();  // its 1D substeps, in every coupling pass; coupled_volume_ from them
  void take_substeps();    // the 1D substeps of the 0D step being taken, from its start
  void keep_pass_start();       // pass_start_ from the 1D vessels now (the step's start)
  void return_to_pass_start();  // the 1D vessels, and the clock, back to pass_start_
  // The passes that cost least per cycle with a 0D step of a thousandth of the period per
  // pass (options' coupling_passes where given).
  int choose_coupling_passes(const SolverOptions& options) const;
  // The constructor's steps (pulse_solver.cpp), after the tube laws and the models.
  std::optional<SteadyFlow> solve_steady_flow();  // none where the network has none: why kept
  // A pressure boundary counts as "in" or "out" by its steady flow (without one: as built).
  void orient_pressure_boundaries(const std::optional<SteadyFlow>& steady);
  // Over ranks: this rank's 0D vessels of the cut the caller's partition makes, its link, and
  // which vessels and outlets it steps.
  void take_rank_share(const PulseRanks& ranks, const SolverOptions& options);
  // The same with the 1D vessels spread over the ranks (one_d_over_ranks.cpp).
  void take_spread_share(const PulseRanks& ranks, const VesselRanks& dealt);
  // Per vessel, what a step of it costs [s] (pulse/step_cost.hpp): a partition's weights.
  std::vector<double> vessel_step_costs(const SolverOptions& options) const;
  void couple_lumped_ends();  // the 1D ends at 0D nodes: their nodes, slots, held inflows
  void allocate_state();      // the state's and the point values' storage
  void choose_models(const SolverOptions& options);
  void start_from_steady_flow(const SteadyFlow& steady);
  // Then the linear periodic state about it at t = 0: pressures and flows along every vessel.
  void start_from_periodic(const PeriodicInstant& instant);
  // Over ranks, the lead's periodic start (instant: the lead's, none elsewhere) on every rank;
  // whether it took one (started: the lead's own outcome). Collective.
  bool take_lead_start(bool started, const std::optional<PeriodicInstant>& instant);
  // Per vessel, from the mean areas [m^3]; over ranks on the lead alone (empty elsewhere),
  // each rank sending its own vessels'.
  std::vector<double> vessel_volumes() const;
  double vessel_volume(std::size_t vessel) const;  // an own vessel's
  double area_per_pressure_at(std::size_t vessel, double volume) const;  // dA/dp at its mean area [m^2/Pa]
  void start_at_rest();
  // steady: the network's steady flow, or null where it has none.
  void choose_degrees_and_elements(const SolverOptions& options, const SteadyFlow* steady);
  std::int32_t end_element(std::size_t vessel) const {
    return zero_d_[vessel] ? first_element(vessel) : first_element(vessel) + elements_per_vessel_;
  }
  VesselEnd vessel_end(std::size_t vessel, bool distal) const {  // a 1D vessel's
    return {static_cast<std::int32_t>(vessel), distal ? end_element(vessel) - 1 : first_element(vessel), distal};
  }
  std::vector<double> capacitor_pressures() const;  // per run outlet (NaN: none)
  // A point of a 1D vessel: its element and xi in [-1, 1] there, and the modes' value (pulse_sampling.cpp).
  void locate(std::size_t vessel, double x, std::size_t& element, double& xi) const;
  // f(j, vessel, area, flow, pressure) for the j-th 1D vessel at fraction x, in parallel
  // (pressure 0 unless with_pressure).
  template <class F>
  void for_each_one_d_sample(double x, bool with_pressure, F&& f) const;
  double evaluate_modes(const Eigen::MatrixXd& coefficients, std::size_t element, double xi) const;

  const Network& net_;
  double period_ = 1;                      // driving_waveform(net)'s
  // Per run outlet (formats/run_boundaries.hpp), where any is RCR (else empty: a tree's two
  // million capillary outlets have none): its capacitance (an RCR's C, else 0) [m^3/Pa]; the
  // outlets themselves are in boundaries_.list. Over ranks the lead's alone (its balance).
  std::size_t outlet_count_ = 0;
  std::vector<double> outlet_capacitance_;
  bool rcr_outlets_ = false;  // any outlet RCR: the compliance balance moves capacitors
  std::vector<double> lumped_inflow_, lumped_held_;  // the 0D nodes' boundary values at a step's end
  Blood blood_;
  ViscosityTable viscosity_;
  // Each vessel's tube law (a tapered one's at its `from` end): whole while the constructor
  // sets up, then as its three numbers per vessel (the blood's density and momentum factor
  // are every vessel's: 24 B a vessel where a TubeLaw takes 40), and whole again per 1D
  // element, where the fluxes read it (law() and end_law() give them).
  std::vector<TubeLaw> laws_;
  std::vector<double> law_beta_, law_area_, law_pressure_;
  std::vector<TubeLaw> element_law_;
  // Tapered vessels (none in most networks: then taper_of_ is empty and nothing below is
  // touched): per vessel its taper's index or -1; per taper its description and distal law.
  std::vector<std::int32_t> taper_of_;
  std::vector<VesselTaper> tapers_;
  std::vector<TubeLaw> distal_laws_;
  // Per element of a tapered vessel (a row): beta and the source coefficients g1, g0 at its
  // quadrature points, the law at its right interface, and the rest-state correction of the
  // flow's rate (modes); taper_row_ per element (-1: untapered; empty without tapers).
  std::vector<std::int32_t> taper_row_, tapered_elements_;
  Eigen::MatrixXd taper_beta_, taper_g1_, taper_g0_, taper_rest_;
  std::vector<TubeLaw> taper_right_law_;
  void build_taper_tables();
  // The tapered elements' rates at the rest state: what the discrete operator leaves of an
  // exact balance (quadrature, differences), subtracted in every evaluation.
  void compute_rest_correction();
  // L2 projection of f(x), x in [0, 1] along 1D vessel v, onto its elements' rows of coefficients.
  template <class F>
  void project_along(std::size_t v, const F& f, Eigen::MatrixXd& coefficients) const;
  // Elements are numbered by degree, so that each degree is one block of rows that the
  // basis of that degree acts on at once; rows have the columns of the highest degree
  // (unused modes stay zero).
  std::vector<bool> zero_d_;               // per vessel
  std::vector<std::uint8_t> lumped_sections_;  // per vessel, where a 0D vessel takes more than one (else empty), until lumped_ is built
  std::size_t sectioned_count_ = 0;
  LumpedVessels lumped_;
  std::optional<std::size_t> lumped_count_after_release_;  // release_lumped_state()
  int substeps_ = 1;
  int coupling_passes_ = 1;
  // The 1D vessels' state and their scheme's history at the 0D step's start, for a pass after
  // the first to start from (keep_pass_start, return_to_pass_start).
  struct PassStart {
    PulseState state, previous_rate;
    Eigen::MatrixXd previous_flow;
    std::vector<EndState> ends;  // the junctions' Newton guesses
    bool had_previous_rate = false;
  } pass_start_;
  double stable_1d_ = 0;                   // the 1D vessels' stable step (inf without any)
  double step_start_ = 0;                  // time at the start of the 0D step being taken
  std::vector<std::int32_t> coupled_node_; // per coupled end: its 0D node
  std::vector<double> held_end_flow_;      // per coupled end: its inflow to the node at the step's start
  std::vector<double> coupled_inflow_, coupled_volume_;  // per coupling node (LumpedVessels' order)
  std::vector<std::int32_t> one_d_vessels_, one_d_first_element_;  // the 1D vessels stepped here, and their first elements
  std::vector<std::int32_t> coupled_slot_;                 // per coupled end: its coupling node's place there
  std::vector<ModalBasis> bases_;          // by degree; empty where unused
  std::vector<ElementRun> blocks_;
  std::vector<ElementRun> runs_;  // the rows this rank steps: blocks_, or its part of them
  // The 1D vessels spread over ranks: the cut, its messages' scratch, and the links.
  std::optional<OneDCut> one_d_cut_;
  std::vector<std::int32_t> vessel_rank_;  // per vessel where the 1D vessels are spread
  std::vector<std::int32_t> lumped_node_rank_;  // per network node, likewise
  std::vector<std::vector<double>> trace_out_, trace_in_;
  std::vector<int> trace_ranks_;
  // The coupled ends whose node another rank holds (spread; empty elsewhere): the cut, each
  // such end's node (start pressure, prediction, impedance, dynamic pressure) as its rank
  // sent it, the messages' scratch, and per coupled end the value sent or received.
  std::optional<CouplingCut> coupling_cut_;
  std::vector<int> coupling_ranks_;
  std::vector<std::array<double, 4>> remote_node_;
  std::vector<std::vector<double>> coupling_out_, coupling_in_;
  std::vector<double> end_volume_;
  void send_to_nodes(std::vector<double>& per_end);  // each cut end's value to its node's rank
  void share_coupling_nodes();                       // each cut node's pressures to its ends' ranks
  void sum_held_inflows();                           // coupled_inflow_ from held_end_flow_
  std::function<void(std::span<const int>, const std::vector<std::vector<double>>&, std::vector<std::vector<double>>&)> exchange_;
  std::function<std::int64_t(std::int64_t)> least_key_;
  // Whether an end's vessel is stepped here.
  bool steps_end(const VesselEnd& end) const { return steps_vessel_.empty() || steps_vessel_[static_cast<std::size_t>(end.vessel)]; }
  bool lumped_in_run_ = false;  // any 0D vessel on any rank: a step is a 0D step around 1D substeps
  // Whether this rank steps a 0D system (spread over ranks a rank may have none).
  bool steps_lumped() const { return !lumped_.empty() || lumped_.over_ranks() || lumped_.halo(); }
  // Spread over ranks: the times of this step's evaluations so far, and its first failure here
  // (the evaluation's place times failure_keys() plus the key: an element's index, or the
  // elements' count plus a junction's), or no_failure.
  static constexpr std::int64_t no_failure = std::numeric_limits<std::int64_t>::max();
  std::vector<double> evaluation_times_;
  std::int64_t first_failure_ = no_failure;
  std::int64_t failure_keys() const {
    return static_cast<std::int64_t>(element_vessel_.size() + boundaries_.junction_offset.size());
  }
  std::int64_t failed_vessel(std::int64_t key) const;  // the id of the vessel a failure's key names
  // The first failure of this step on any rank, thrown on every rank as the one process would
  // throw it (the same vessel, the same time); the step's record cleared. Collective.
  void settle_failures();
  std::vector<std::int8_t> vessel_degree_;  // per vessel: -1 (0D) to 30 (run_configuration)
  int elements_per_vessel_ = 1;
  // Each 1D vessel's first element, by vessel (increasing): its elements are consecutive. Only
  // the 1D vessels' (a tree's millions of 0D vessels have none): first_element(v) finds it.
  std::vector<std::pair<std::int32_t, std::int32_t>> first_elements_;
  std::vector<std::int32_t> element_vessel_; // per element
  Eigen::VectorXd half_length_;            // per element: the Jacobian J = h / 2
  Eigen::VectorXd element_beta_;           // per element
  double friction_k_ = 0;                  // 2 pi alpha / (alpha - 1)
  NetworkBoundaries boundaries_;
  // Per boundary: its place in state_.boundary (a 1D end's) or -1; and the volumes in through
  // the others, at 0D nodes (LumpedVessels::complete sums them; the 1D entries stay 0).
  std::vector<std::int32_t> boundary_slot_;
  std::vector<double> lumped_boundary_volume_;

  PulseState state_, rate_, previous_rate_, stage_[4];
  // Per element: the friction rate r = k mu(A_mean) / (rho A_mean) the last evaluate() used;
  // for the exponential scheme, the previous step's flow coefficients.
  Eigen::VectorXd friction_rate_;
  std::vector<double> viscosity_factor_;  // per vessel (empty: 1)
  Eigen::VectorXd element_viscosity_factor_;  // per element (empty: 1)
  // Poiseuille at the steady state, per vessel; empty without a steady solution. Only what
  // the balance falls back on (before a cycle's mean, or for a lumen closed at it): a
  // linearisation's conductance, in float. Over ranks the lead's alone, as the marks below.
  std::vector<float> steady_resistance_;
  bool can_balance_ = false;               // whether the run has a steady solution (every rank alike)
  std::vector<double> cycle_volume_;       // per vessel, at the last cycle end
  std::vector<double> cycle_capacitor_;    // the capacitors there, per network outlet
  bool cycle_marked_ = false;              // whether the marks are set (every rank alike)
  // The balance's parts: the moves of the nodes and capacitors (the lead's, from the whole
  // network's volumes), and each rank's own 1D elements and capacitors moved by them.
  TreePotentials compliance_moves(double period, std::vector<double> mean_pressure, const std::vector<double>& volume,
                                  const std::vector<double>& area_per_pressure, const std::vector<double>& capacitor_now);
  void move_compliances(const TreePotentials& move, const std::vector<double>& element_area_per_pressure);
  Eigen::VectorXd decay_, phi1_, phi2_, next_flow_;  // ETD2: e^(-r h), phi1, phi2 per element; scratch
  Eigen::MatrixXd previous_flow_;
  bool have_previous_rate_ = false;
  bool tracking_faces_ = false;
  TimeScheme scheme_;
  int threads_ = 1;
  bool one_d_here_ = true;  // false on a share of a run over ranks (PulseRanks)
  int rank_ = 0, rank_count_ = 1;  // over ranks: this rank's, of how many
  // Over ranks: PulseRanks' make_whole, lead_whole, lead_places, from_lead and lead_rank (the
  // compliance balance's inputs go to the lead, its moves come back from it; a checkpoint's
  // arrays go to the lead).
  std::function<void(std::vector<double>&, const std::vector<unsigned char>&)> make_whole_, lead_whole_;
  std::function<std::vector<double>(std::span<const double>, std::span<const std::int32_t>, std::size_t)> lead_places_;
  std::function<void(std::vector<double>&)> from_lead_;
  int lead_rank_ = 0;
  // save()'s section "pulse solver", with each boundary's 0D volume and the viscosity factors
  // (whole over ranks).
  // The 1D vessels' evolving state as save() writes it: this rank's, or (spread over ranks) made
  // whole on the lead rank.
  struct OneDState {
    const PulseState *state, *previous_rate;
    const Eigen::MatrixXd* previous_flow;
    std::function<EndState(std::size_t vessel, bool distal)> end_state;
  };
  void save_section(CheckpointWriter& out, const std::vector<double>& lumped_boundary_volume,
                    const std::vector<double>& viscosity_factor, const OneDState& one_d) const;
  // save_over_ranks' 1D state with the vessels spread: every array whole on the lead rank
  // (one_d_over_ranks.cpp); `whole` holds it.
  struct WholeOneD {
    PulseState state, previous_rate;
    Eigen::MatrixXd previous_flow;
    std::vector<double> ends;  // per 1D vessel (vessel order): proximal (A, Q), distal (A, Q)
  };
  WholeOneD whole_one_d_state() const;
  // Over ranks: whether this rank steps each vessel and holds each run outlet's state.
  std::vector<unsigned char> steps_vessel_, holds_outlet_;
  double time_ = 0, dt_ = 0;
  std::string dt_reason_;
  double stable_dt_ = 0;
  std::string stable_dt_reason_;
  std::size_t steps_ = 0;
  bool started_from_steady_ = false;
  StartChoice started_from_ = StartChoice::rest;
  std::string steady_refusal_, periodic_refusal_;
  double steady_pressure_min_ = std::numeric_limits<double>::quiet_NaN();
  double steady_pressure_max_ = std::numeric_limits<double>::quiet_NaN();
  std::size_t steady_pressure_max_vessel_ = 0;

  // Scratch, sized once: values at quadrature points and traces.
  Eigen::MatrixXd area_q_, flow_q_, flux_q_, source_q_;
  Eigen::VectorXd area_left_, area_right_, flow_left_, flow_right_;
  Eigen::VectorXd flux_a_left_, flux_a_right_, flux_q_left_, flux_q_right_;
};

}  // namespace hemotree
