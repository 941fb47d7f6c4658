// PulseSolver set up from a network and options: each vessel's tube law, the 1D/0D choice,
// degrees and elements (blocks of rows by degree), the taper tables, the boundaries and the
// 1D-0D coupling, the initial state (steady or at rest); and the transport's hooks (viscosity
// factors, face volumes). Its other concepts have their own files: the DG rate (dg_rate.cpp),
// the time step and schemes (pulse_time_stepping.cpp), the solution read out
// (pulse_sampling.cpp), the checkpoint (pulse_solver_checkpoint.cpp) and the compliance
// balance (compliance_balance.cpp).
#include "pulse/pulse_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "core/errors.hpp"
#include "core/setting_error.hpp"
#include "core/parallel_errors.hpp"
#include "pulse/solution_breakdown.hpp"
#include "formats/connected_parts.hpp"
#include "physics/poiseuille.hpp"
#include "physics/wall_law.hpp"
#include "steady/steady_flow.hpp"
#include "steady/vessel_laws.hpp"

namespace hemotree {

void PulseState::set_zero_like(const PulseState& other) {
  area.setZero(other.area.rows(), other.area.cols());
  flow.setZero(other.flow.rows(), other.flow.cols());
  capacitor.setZero(other.capacitor.size());
  coupled.setZero(other.coupled.size());
  boundary.setZero(other.boundary.size());
  faces.setZero(other.faces.size());
}

void PulseState::add_scaled(double factor, const PulseState& other) {
  area += factor * other.area;
  flow += factor * other.flow;
  capacitor += factor * other.capacitor;
  coupled += factor * other.coupled;
  boundary += factor * other.boundary;
  faces += factor * other.faces;
}

namespace {
Blood effective_blood(const Network& net, const SolverOptions& options) {
  Blood blood = net.blood.value_or(Blood{});
  if (options.rheology_override >= 0) blood.rheology = static_cast<Rheology>(options.rheology_override);
  return blood;
}
}  // namespace

PulseSolver::PulseSolver(const Network& net, const SolverOptions& options, const PulseRanks* ranks)
    : net_(net), blood_(effective_blood(net, options)), viscosity_(blood_),
      scheme_(options.scheme) {
  if (options.degree < 0 && options.degree != SolverOptions::automatic)
    throw SettingError("degree", placeholder("degree") + " must be at least 0");
  if (options.elements < 1) throw SettingError("elements", placeholder("elements") + " must be at least 1");
  if (options.threads < 1) throw SettingError("threads", placeholder("threads") + " must be at least 1");
  threads_ = options.threads;
  friction_k_ = friction_coefficient(blood_.alpha);
  const std::size_t n = net.vessel_count();
  if (ranks) {  // who leads (leads()): the lead alone solves the periodic start and the balances
    rank_ = ranks->rank;
    from_lead_ = ranks->from_lead;
    lead_rank_ = ranks->lead_rank;
  }

  // Each vessel's tube law (steady/vessel_laws.hpp); a tapered vessel's along it.
  laws_ = vessel_laws(net, blood_, options.external_pressure, options.thick_wall_ratio);
  for (std::size_t v = 0; v < n; ++v) {
    TubeLaw& law = laws_[v];
    if (net.is_tapered(v)) {
      // The law along the vessel (physics/vessel_taper.hpp): the wall's h and E, or the given
      // beta at the proximal diameter, with the proximal diameter's wall model.
      VesselTaper taper;
      taper.d0 = net.diameter[v];
      taper.d1 = net.distal_diameter[v];
      taper.length = net.length[v];
      taper.density = blood_.density;
      taper.alpha = blood_.momentum_alpha();
      taper.given_beta = !net.beta.empty() && !std::isnan(net.beta[v]);
      taper.beta0 = law.beta;
      taper.reference_pressure = law.reference_pressure;
      if (!taper.given_beta) {
        taper.wall = {net.diameter[v], net.wall_thickness[v], net.youngs_modulus[v]};
        taper.model = choose_wall_model(taper.wall, options.thick_wall_ratio);
        taper.external_pressure = options.external_pressure;
      }
      if (taper_of_.empty()) taper_of_.assign(n, -1);
      taper_of_[v] = static_cast<std::int32_t>(tapers_.size());
      tapers_.push_back(taper);
      law = taper.at(0);
      distal_laws_.push_back(taper.at(1));
    }
  }

  period_ = driving_waveform(net).period;
  const RunBoundaries boundaries(net);
  for (std::size_t i = 0; i < boundaries.size(); ++i)
    if (boundaries.is_outlet(i)) {
      ++outlet_count_;
      rcr_outlets_ = rcr_outlets_ || boundaries.outlet(i).type == BoundaryType::rcr;
    }
  if (rcr_outlets_) {
    outlet_capacitance_.reserve(outlet_count_);
    for (std::size_t i = 0; i < boundaries.size(); ++i)
      if (const Outlet& o = boundaries.outlet(i); boundaries.is_outlet(i))
        outlet_capacitance_.push_back(o.type == BoundaryType::rcr ? o.c : 0.0);
  }
  choose_models(options);

  std::optional<SteadyFlow> steady = solve_steady_flow();
  choose_degrees_and_elements(options, steady ? &*steady : nullptr);
  {
    std::vector<std::int32_t> first(n, -1);
    for (const auto& [v, el] : first_elements_) first[static_cast<std::size_t>(v)] = el;
    boundaries_ = build_boundaries(net, first, elements_per_vessel_, zero_d_);
  }
  // The steady solve's rule (docs/network-format.md), once the boundaries' own form is checked:
  // a part with flow boundaries only has no pressure level, and a run from rest over it was
  // called complete (hostile-inputs 05), or failed deep in the 0D solve.
  if (const std::string refusal = pressure_reference_refusal(net, boundaries_.list); !refusal.empty())
    throw SettingError("pressure_at", refusal);
  orient_pressure_boundaries(steady);

  // The linear periodic state, before the 0D vessels' arrays exist: its harmonic workspace and
  // those arrays are the set-up's two largest parts, and need not be held at once.
  started_from_steady_ = options.start != StartChoice::rest && steady;
  std::optional<PeriodicInstant> instant;
  // Over ranks the lead alone solves it, whole, and sends every rank its start (below): its
  // workspace, about 120 B a vessel, was every rank's largest moment.
  if (started_from_steady_ && options.start == StartChoice::periodic && leads()) {
    // Where the linear periodic state cannot be formed (a harmonic's system singular where
    // the steady one is not: no input is known to reach this, and the default start should
    // not be what fails a run), the run keeps the steady start and says why.
    try {
      std::vector<bool> one_d = zero_d_;  // the vessels whose whole state it keeps
      one_d.flip();
      instant = solve_periodic_instant(net, blood_, laws_, viscosity_, *steady, boundaries_.list,
                                       options.periodic_harmonics, time_, one_d, threads_, true);
    } catch (const InputError& e) {
      periodic_refusal_ = e.what();
    }
  }

  lumped_in_run_ = lumped_vessels_in_run() > 0;
  runs_ = blocks_;
  one_d_first_element_.clear();
  for (std::size_t j = 0; j < one_d_vessels_.size(); ++j)
    one_d_first_element_.push_back(static_cast<std::int32_t>(j) * elements_per_vessel_);
  if (ranks) {
    take_rank_share(*ranks, options);
    if (!leads()) {  // the balance is the lead's
      std::vector<float>().swap(steady_resistance_);
      std::vector<double>().swap(outlet_capacitance_);
    }
  } else
    lumped_ = LumpedVessels(net, laws_, viscosity_, blood_, zero_d_, taper_of_, tapers_, lumped_sections_);
  sectioned_count_ = static_cast<std::size_t>(std::count_if(lumped_sections_.begin(), lumped_sections_.end(), [](std::uint8_t s) { return s > 1; }));
  std::vector<std::uint8_t>().swap(lumped_sections_);  // a byte a vessel the run no longer reads
  lumped_.set_passes(options.lumped_passes);
  lumped_.set_threads(threads_);
  couple_lumped_ends();
  allocate_state();

  compute_rest_correction();
  if (started_from_steady_) {
    start_from_steady_flow(*steady);
    // Read no more: freed before the laws' compact form is made beside them (the set-up's
    // largest moment on a rank of a run over ranks, 16 B a vessel).
    steady.reset();
    started_from_ = StartChoice::steady;
    bool periodic = false;
    if (instant) {
      try {
        start_from_periodic(*instant);
        periodic = true;
      } catch (const InputError& e) {
        periodic_refusal_ = e.what();
      }
    }
    if (ranks && options.start == StartChoice::periodic) periodic = take_lead_start(periodic, instant);
    if (periodic) started_from_ = StartChoice::periodic;
    instant.reset();
  } else {
    start_at_rest();
  }
  choose_time_step(options);
  // The coupled ends' first linearisation needs their end states.
  if (!coupling_ranks_.empty()) share_coupling_nodes();
  if (!boundaries_.coupled.empty() && one_d_here_) evaluate(time_, state_, rate_);
  if (one_d_cut_) settle_failures();

  law_beta_.resize(n);
  law_area_.resize(n);
  law_pressure_.resize(n);
  for (std::size_t v = 0; v < n; ++v) {
    law_beta_[v] = laws_[v].beta;
    law_area_[v] = laws_[v].reference_area;
    law_pressure_[v] = laws_[v].reference_pressure;
  }
  std::vector<TubeLaw>().swap(laws_);
}

std::optional<SteadyFlow> PulseSolver::solve_steady_flow() {
  const Network& net = net_;
  // The steady Poiseuille solution, where the network has one (not with reflection outlets):
  // the degrees follow its pressure profiles, and the run starts from it.
  std::optional<SteadyFlow> steady;
  // (A network with node boundaries takes their means; a tree, its inlet's.)
  try {
    std::vector<double> resistance;
    steady = solve_distended_steady_flow(net, blood_, laws_, viscosity_, net.inlet ? net.inlet->waveform.mean_value() : 0.0,
                                         &resistance, threads_);
    steady_resistance_.assign(resistance.begin(), resistance.end());
    can_balance_ = true;
  } catch (const InputError& e) {
    steady_refusal_ = e.what();
  }
  if (steady) {
    const auto [low, high] = std::minmax_element(steady->node_pressure.begin(), steady->node_pressure.end());
    steady_pressure_min_ = *low;
    steady_pressure_max_ = *high;
    const auto node = high - steady->node_pressure.begin();  // the inlet's node, as a rule
    const auto entering = std::find(net.to.begin(), net.to.end(), node), leaving = std::find(net.from.begin(), net.from.end(), node);
    steady_pressure_max_vessel_ = static_cast<std::size_t>(
        entering != net.to.end() ? entering - net.to.begin() : leaving - net.from.begin());
  }
  return steady;
}

void PulseSolver::orient_pressure_boundaries(const std::optional<SteadyFlow>& steady) {
  const Network& net = net_;
  const std::size_t n = net.vessel_count();
  if (steady) {
    // A pressure boundary counts as "in" or "out" by its steady flow.
    std::vector<double> inflow(net.node_count(), 0.0);
    for (std::size_t v = 0; v < n; ++v) {
      inflow[static_cast<std::size_t>(net.from[v])] += steady->flow[v];
      inflow[static_cast<std::size_t>(net.to[v])] -= steady->flow[v];
    }
    for (std::size_t i = 0; i < boundaries_.list.size(); ++i)
      if (boundaries_.list.type(i) == BoundaryType::pressure)
        boundaries_.entering[i] = inflow[static_cast<std::size_t>(boundaries_.list.node(i))] >= 0;
  }
}

void PulseSolver::take_rank_share(const PulseRanks& ranks, const SolverOptions& options) {
  const std::size_t n = net_.vessel_count();
  const VesselRanks dealt = ranks.vessel_ranks(zero_d_, vessel_step_costs(options));
  if (dealt.one_d_spread) {
    take_spread_share(ranks, dealt);
    return;
  }
  // This rank's whole subtrees; the 1D vessels and every vessel above them the top's rank's.
  const std::vector<std::int32_t>& vessel_rank = dealt.rank;
  for (std::size_t v = 0; v < n; ++v)
    if (!zero_d_[v] && vessel_rank[v] != ranks.top_rank)
      throw std::invalid_argument("PulseSolver: 1D vessel " + std::to_string(net_.id[v]) + " on rank " +
                                  std::to_string(vessel_rank[v]) + ", not the top's");
  const LumpedCut cut = lumped_cut(net_, subtree_lumped_order(net_, zero_d_), vessel_rank, ranks.ranks, ranks.top_rank,
                                   ranks.rank, lumped_sections_);
  lumped_ = LumpedVessels(net_, laws_, viscosity_, blood_, zero_d_, taper_of_, tapers_, lumped_sections_, &cut);
  if (ranks.cut_made) ranks.cut_made(cut);
  lumped_.set_link(ranks.link);
  make_whole_ = ranks.make_whole;
  lead_whole_ = ranks.lead_whole;
  lead_places_ = ranks.lead_places;
  rank_ = ranks.rank;
  rank_count_ = ranks.ranks;
  steps_vessel_.assign(n, 0);
  for (std::size_t v = 0; v < n; ++v) {
    const std::int32_t i = lumped_.vessel_index(v);
    steps_vessel_[v] = zero_d_[v] ? i >= 0 && !lumped_.ghost_vessel(i) : cut.top();
  }
  const RunBoundaries run(net_);
  for (std::size_t i = 0; i < run.size(); ++i)
    if (run.is_outlet(i)) holds_outlet_.push_back(steps_vessel_[static_cast<std::size_t>(run.outlet(i).vessel)]);
  // A lumen closing on any rank is said on every rank as this rank would say it alone.
  lumped_.set_failure_words([this](std::exception_ptr failure) {
    try {
      std::rethrow_exception(failure);
    } catch (const LumpedVessels::CollapsedNode& collapsed) {
      return std::make_exception_ptr(SolutionBreakdown(net_.id[static_cast<std::size_t>(collapsed.vessel)], time_));
    } catch (...) {
      return failure;
    }
  });
  one_d_here_ = cut.top();
  if (!one_d_here_) {  // the top's
    one_d_vessels_.clear();
    one_d_first_element_.clear();
  }
}

void PulseSolver::couple_lumped_ends() {
  lumped_inflow_.assign(lumped_.inflow_boundaries().size(), 0.0);
  lumped_held_.assign(lumped_.held_boundaries().size(), 0.0);
  if (!one_d_here_) return;  // every coupled end is the top's
  // With the 1D vessels spread over ranks, a coupled end's node may be another rank's (slot
  // -1): in a halo, a ghost is.
  for (const auto& c : boundaries_.coupled) {
    const std::int32_t k = lumped_.node_of(c.node);
    coupled_node_.push_back(k >= 0 && lumped_.ghost_node(k) ? -1 : k);
  }
  std::vector<std::int32_t> nodes;
  for (const std::int32_t node : coupled_node_)
    if (node >= 0) nodes.push_back(node);
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  for (const std::int32_t node : coupled_node_)
    coupled_slot_.push_back(node < 0 ? -1 : static_cast<std::int32_t>(std::lower_bound(nodes.begin(), nodes.end(), node) - nodes.begin()));
  coupled_inflow_.assign(nodes.size(), 0.0);
  lumped_.set_coupling_nodes(std::move(nodes));
  if (lumped_.halo()) {  // the run's coupling nodes, every rank's alike
    std::vector<std::int64_t> coupled;
    for (const auto& c : boundaries_.coupled) coupled.push_back(c.node);
    std::sort(coupled.begin(), coupled.end());
    coupled.erase(std::unique(coupled.begin(), coupled.end()), coupled.end());
    lumped_.set_halo_coupling(coupled);
  }
  held_end_flow_.assign(boundaries_.coupled.size(), 0.0);
  coupled_volume_ = coupled_inflow_;
}

void PulseSolver::allocate_state() {
  const auto rows = static_cast<Eigen::Index>(element_vessel_.size());
  Eigen::Index points = 0;
  for (const ElementRun& b : blocks_) points = std::max<Eigen::Index>(points, bases_[b.degree].points);
  const Eigen::Index modes = max_degree() + 1;
  state_.area.setZero(rows, modes);
  state_.flow.setZero(rows, modes);
  state_.capacitor.setZero(static_cast<Eigen::Index>(boundaries_.capacitors));
  state_.coupled.setZero(static_cast<Eigen::Index>(boundaries_.coupled.size()));
  state_.boundary.setZero(static_cast<Eigen::Index>(boundaries_.one_d_boundary.size()));
  boundary_slot_.assign(boundaries_.list.size(), -1);
  for (std::size_t j = 0; j < boundaries_.one_d_boundary.size(); ++j)
    boundary_slot_[static_cast<std::size_t>(boundaries_.one_d_boundary[j])] = static_cast<std::int32_t>(j);
  lumped_boundary_volume_.assign(boundaries_.list.size(), 0.0);
  area_q_.resize(rows, points);
  flow_q_.resize(rows, points);
  flux_q_.resize(rows, points);
  source_q_.resize(rows, points);
}

void PulseSolver::choose_models(const SolverOptions& options) {
  const std::size_t n = net_.vessel_count();
  zero_d_.assign(n, options.model == ModelChoice::zero_d);
  if (options.model != ModelChoice::automatic) return;
  // A vessel moves in phase along its length, as a lumped element, when |gamma L| =
  // |sqrt((R + i w L_q) i w C)| is small at the pulse's frequencies (R, L_q, C the vessel's
  // own resistance, inertance and compliance). Its two limits are the two tests: where
  // friction is weak (arteries), w L / c, bounded by the wave transit L / c against
  // --lumped-transit of the period; where it dominates (capillaries), w R C, the pressure's
  // diffusion along the vessel, bounded at the fundamental by --lumped-rc (docs/solver.md §10
  // gives the measurements behind both).
  std::vector<bool> reflecting(n, false), reflecting_node(net_.node_count(), false);
  const RunBoundaries boundaries(net_);  // before build_boundaries
  for (std::size_t i = 0; i < boundaries.size(); ++i)
    if (boundaries.type(i) == BoundaryType::reflection) reflecting_node[static_cast<std::size_t>(boundaries.node(i))] = true;
  for (std::size_t v = 0; v < n; ++v)
    reflecting[v] = reflecting_node[static_cast<std::size_t>(net_.from[v])] || reflecting_node[static_cast<std::size_t>(net_.to[v])];
  const double period = period_, omega = 2 * std::numbers::pi / period;
  for (std::size_t v = 0; v < n; ++v) {
    const TubeLaw& law = laws_[v];
    const double area = law.reference_area, length = net_.length[v];
    double transit = length / law.wave_speed(area);
    double compliance = law.compliance(length, area);
    double resistance = friction_k_ * viscosity_(area) * length / (area * area);
    if (is_tapered(v)) {
      // The same integrals along the vessel: int dx / c, int dA/dp dx, int k mu / A^2 dx.
      const VesselTaper& taper = tapers_[static_cast<std::size_t>(taper_of_[v])];
      transit = compliance = 0;
      for (std::size_t i = 0; i < taper_rule_nodes.size(); ++i) {
        const TubeLaw at = taper.at(taper_rule_nodes[i]);
        const double a = taper.rest_area(taper_rule_nodes[i]);
        transit += taper_rule_weights[i] * length / at.wave_speed(a);
        compliance += at.compliance(taper_rule_weights[i] * length, a);
      }
      resistance = tapered_poiseuille_resistance(
          [&](double d) { return viscosity_(std::numbers::pi / 4 * d * d); }, length, taper.d0, taper.d1, blood_.alpha);
    }
    int sections = reflecting[v] ? 0 : options.lumped_sections_of(transit, omega * resistance * compliance, period);
    if (sections > 1 && is_tapered(v)) sections = 0;  // a tapered vessel stays one section: 1D where one is too few
    zero_d_[v] = sections > 0;
    if (sections > 1) {
      if (lumped_sections_.empty()) lumped_sections_.assign(n, 1);
      lumped_sections_[v] = static_cast<std::uint8_t>(sections);
    }
  }
}

void PulseSolver::choose_degrees_and_elements(const SolverOptions& options, const SteadyFlow* steady) {
  const std::size_t n = net_.vessel_count();
  const int e = options.elements;
  elements_per_vessel_ = e;
  if (options.degree == SolverOptions::automatic) {
    std::vector<double> transit(n), linear_error;
    for (std::size_t v = 0; v < n; ++v) {
      transit[v] = zero_d_[v] ? std::numeric_limits<double>::infinity()  // no step limit of its own
                              : net_.length[v] / e / laws_[v].wave_speed(laws_[v].reference_area);
      if (!zero_d_[v] && is_tapered(v))  // the faster end sets it
        transit[v] = std::min(transit[v], net_.length[v] / e / end_law(v, true).wave_speed(end_law(v, true).reference_area));
    }
    if (steady) {
      // Over one element of the vessel: its share of the drop.
      linear_error.resize(n);
      for (std::size_t v = 0; v < n; ++v) {
        const double p_in = steady->node_pressure[net_.from[v]], p_out = steady->node_pressure[net_.to[v]];
        linear_error[v] = linear_profile_error(laws_[v], viscosity_, p_in, p_in + (p_out - p_in) / e);
      }
    }
    const double period = period_;
    const std::vector<int> chosen = choose_degrees(transit, linear_error, period, options.degree_rule,
                                                   scheme_ == TimeScheme::runge_kutta4 ? TimeScheme::runge_kutta4
                                                                                       : TimeScheme::adams_bashforth2);
    vessel_degree_.assign(chosen.begin(), chosen.end());
  } else {
    vessel_degree_.assign(n, static_cast<std::int8_t>(options.degree));
  }
  std::size_t one_d = 0;
  for (std::size_t v = 0; v < n; ++v) {
    if (zero_d_[v]) vessel_degree_[v] = -1;
    else ++one_d;
    // A tapered vessel's rest lumen pi D(x)^2 / 4 is quadratic in x: degree 2 holds it
    // exactly, and with it the rest state (well-balanced, docs/solver.md §1a).
    if (!zero_d_[v] && is_tapered(v)) vessel_degree_[v] = std::max<std::int8_t>(vessel_degree_[v], 2);
  }
  const int top = std::max(0, n == 0 ? 0 : *std::max_element(vessel_degree_.begin(), vessel_degree_.end()));
  bases_.assign(static_cast<std::size_t>(top) + 1, ModalBasis{});
  first_elements_.clear();
  element_vessel_.resize(one_d * static_cast<std::size_t>(e));
  half_length_.resize(static_cast<Eigen::Index>(element_vessel_.size()));
  element_beta_.resize(half_length_.size());
  element_law_.resize(element_vessel_.size());
  blocks_.clear();
  one_d_vessels_.clear();
  std::int32_t next = 0;
  for (int p = 0; p <= top; ++p) {
    const std::int32_t first = next;
    for (std::size_t v = 0; v < n; ++v) {
      if (vessel_degree_[v] != p) continue;
      first_elements_.emplace_back(static_cast<std::int32_t>(v), next);
      for (int k = 0; k < e; ++k, ++next) {
        element_vessel_[static_cast<std::size_t>(next)] = static_cast<std::int32_t>(v);
        half_length_(next) = net_.length[v] / (2.0 * e);
        element_beta_(next) = laws_[v].beta;
        element_law_[static_cast<std::size_t>(next)] = laws_[v];
      }
    }
    if (next == first) continue;
    for (std::int32_t el = first; el < next; el += e) one_d_vessels_.push_back(element_vessel_[static_cast<std::size_t>(el)]);
    bases_[static_cast<std::size_t>(p)] = modal_basis(p, options.quadrature_points);
    blocks_.push_back({p, first, next - first});
  }
  std::sort(first_elements_.begin(), first_elements_.end());  // by vessel (they came by degree)
  build_taper_tables();
}

void PulseSolver::build_taper_tables() {
  taper_row_.clear();
  tapered_elements_.clear();
  taper_right_law_.clear();
  if (tapers_.empty()) return;
  const auto elements = static_cast<Eigen::Index>(element_vessel_.size());
  taper_row_.assign(element_vessel_.size(), -1);
  for (Eigen::Index el = 0; el < elements; ++el)
    if (is_tapered(static_cast<std::size_t>(element_vessel_[static_cast<std::size_t>(el)]))) {
      taper_row_[static_cast<std::size_t>(el)] = static_cast<std::int32_t>(tapered_elements_.size());
      tapered_elements_.push_back(static_cast<std::int32_t>(el));
    }
  Eigen::Index points = 1;
  for (const ElementRun& b : blocks_) points = std::max<Eigen::Index>(points, bases_[static_cast<std::size_t>(b.degree)].points);
  const auto rows = static_cast<Eigen::Index>(tapered_elements_.size());
  taper_beta_.setZero(rows, points);
  taper_g1_.setZero(rows, points);
  taper_g0_.setZero(rows, points);
  taper_rest_.setZero(rows, max_degree() + 1);
  const int e = elements_per_vessel_;
  for (Eigen::Index row = 0; row < rows; ++row) {
    const auto el = tapered_elements_[static_cast<std::size_t>(row)];
    const auto v = static_cast<std::size_t>(element_vessel_[static_cast<std::size_t>(el)]);
    const VesselTaper& taper = tapers_[static_cast<std::size_t>(taper_of_[v])];
    const ModalBasis& basis = bases_[static_cast<std::size_t>(vessel_degree_[v])];
    const int k = el - first_element(v);
    for (Eigen::Index q = 0; q < basis.points; ++q) {
      const double s = (k + 0.5 * (basis.rule.nodes(q) + 1)) / e;
      taper_beta_(row, q) = taper.at(s).beta;
      taper.source_coefficients(s, taper_g1_(row, q), taper_g0_(row, q));
    }
    taper_right_law_.push_back(taper.at(static_cast<double>(k + 1) / e));
  }
}

TubeLaw PulseSolver::law_at(std::size_t vessel, double x) const {
  if (!is_tapered(vessel)) return law(vessel);
  return tapers_[static_cast<std::size_t>(taper_of_[vessel])].at(std::clamp(x, 0.0, 1.0));
}

// ---- initial states --------------------------------------------------------------------

void PulseSolver::start_at_rest() {
  // Every vessel at its reference area and no flow: p = p_ref.
  for (std::size_t v = 0; v < net_.vessel_count(); ++v) {
    if (is_tapered(v) && !zero_d_[v]) {
      // A tapered vessel rests at its measured lumen pi D(x)^2 / 4, where the pressure is the
      // same all along (physics/vessel_taper.hpp): quadratic in x, projected exactly at degree 2.
      const VesselTaper& taper = tapers_[static_cast<std::size_t>(taper_of_[v])];
      project_along(v, [&](double x) { return taper.rest_area(x); }, state_.area);
      continue;
    }
    for (auto el = first_element(v), end = end_element(v); el < end; ++el)
      state_.area(el, 0) = laws_[v].reference_area;
  }
  lumped_.start_at_rest(laws_);
  for (auto& o : boundaries_.outlets) {
    if (o.capacitor >= 0) state_.capacitor(o.capacitor) = o.outlet.p_out;
    const auto v = static_cast<std::size_t>(o.end.vessel);
    o.rest_area = is_tapered(v) ? tapers_[static_cast<std::size_t>(taper_of_[v])].rest_area(o.end.distal ? 1 : 0)
                                : laws_[v].reference_area;
    o.rest_flow = 0;
  }
}

template <class F>
void PulseSolver::project_along(std::size_t v, const F& f, Eigen::MatrixXd& coefficients) const {
  const ModalBasis& basis = bases_[static_cast<std::size_t>(vessel_degree_[v])];
  const auto e = elements_per_vessel_;
  Eigen::VectorXd values(basis.points);
  for (auto k = 0; k < e; ++k) {
    for (Eigen::Index q = 0; q < basis.points; ++q) values(q) = f((k + 0.5 * (basis.rule.nodes(q) + 1)) / e);
    coefficients.row(first_element(v) + k).head(basis.degree + 1) = (basis.projection * values).transpose();
  }
}

void PulseSolver::compute_rest_correction() {
  // The discrete right-hand side of the rest state (Q = 0, A = pi D(x)^2 / 4) in every tapered
  // element, with each element's end fluxes F at its own traces (what the upwind flux and the
  // nodes return there at rest). In exact arithmetic and with exact integrals it vanishes; what
  // remains is the quadrature's error on the non-polynomial flux and source, and the finite
  // differences' in beta' and c'. Subtracting it in every evaluation makes the rest state
  // exact to round-off (the well-balanced property) and changes nothing else beyond that
  // error, which vanishes spectrally as the mesh is refined.
  if (tapered_elements_.empty()) return;
  PulseState rest;
  rest.set_zero_like(state_);
  for (std::size_t v = 0; v < net_.vessel_count(); ++v)
    if (is_tapered(v) && !zero_d_[v]) {
      const VesselTaper& taper = tapers_[static_cast<std::size_t>(taper_of_[v])];
      project_along(v, [&](double x) { return taper.rest_area(x); }, rest.area);
    }
  taper_rest_.setZero();
  const double rho = blood_.density;
  const int e = elements_per_vessel_;
  for (std::size_t row = 0; row < tapered_elements_.size(); ++row) {
    const auto el = tapered_elements_[row];
    const auto v = static_cast<std::size_t>(element_vessel_[static_cast<std::size_t>(el)]);
    const VesselTaper& taper = tapers_[static_cast<std::size_t>(taper_of_[v])];
    const ModalBasis& basis = bases_[static_cast<std::size_t>(vessel_degree_[v])];
    const Eigen::Index modes = basis.degree + 1;
    const Eigen::VectorXd a = rest.area.row(el).head(modes).transpose();
    const Eigen::VectorXd a_q = basis.at_points * a;
    Eigen::VectorXd flux(basis.points), source(basis.points);
    const auto r = static_cast<Eigen::Index>(row);
    for (Eigen::Index q = 0; q < basis.points; ++q) {
      const double root = std::sqrt(a_q(q));
      flux(q) = TubeLaw::pressure_flux(taper_beta_(r, q) / (3 * rho), a_q(q));  // as evaluate's
      source(q) = a_q(q) * (taper_g1_(r, q) * root + taper_g0_(r, q));
    }
    const int k = el - first_element(v);
    const TubeLaw left = taper.at(static_cast<double>(k) / e), right = taper.at(static_cast<double>(k + 1) / e);
    const double flux_left = left.flux_flow((basis.left * a).value(), 0.0);
    const double flux_right = right.flux_flow((basis.right * a).value(), 0.0);
    Eigen::VectorXd rate = basis.weak_derivative * flux -
                           basis.inverse_mass.cwiseProduct(basis.right).transpose() * flux_right +
                           basis.inverse_mass.cwiseProduct(basis.left).transpose() * flux_left;
    rate /= half_length_(el);
    rate += basis.projection * source;
    taper_rest_.row(r).head(modes) = rate.transpose();
  }
}

void PulseSolver::start_from_steady_flow(const SteadyFlow& s) {
  const Network& net = net_;
  lumped_.start(s.node_pressure, s.flow);
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    if (zero_d_[v]) continue;
    const ModalBasis& basis = bases_[static_cast<std::size_t>(vessel_degree_[v])];
    const Eigen::Index points = basis.points;
    const double p0 = s.node_pressure[net.from[v]], p1 = s.node_pressure[net.to[v]];
    const auto e = elements_per_vessel_;
    if (is_tapered(v)) {
      // Pressure linear along the vessel as below, each point's area from the law there.
      const VesselTaper& taper = tapers_[static_cast<std::size_t>(taper_of_[v])];
      project_along(v, [&](double x) { return taper.at(x).area(p0 + (p1 - p0) * x); }, state_.area);
      for (auto k = 0; k < e; ++k) state_.flow(first_element(v) + k, 0) = s.flow[v];
      continue;
    }
    for (auto k = 0; k < e; ++k) {
      // Pressure falls linearly along the vessel; project A(p(x)) onto the modes.
      Eigen::VectorXd a(points);
      for (Eigen::Index q = 0; q < points; ++q) {
        const double x = (k + 0.5 * (basis.rule.nodes(q) + 1)) / e;
        a(q) = laws_[v].area(p0 + (p1 - p0) * x);
      }
      const auto el = first_element(v) + k;
      state_.area.row(el).head(basis.degree + 1) = (basis.projection * a).transpose();
      state_.flow(el, 0) = s.flow[v];
    }
  }
  for (auto& o : boundaries_.outlets) {
    const auto v = static_cast<std::size_t>(o.end.vessel);
    // Its outflow, and the pressure at its node (1D vessels only).
    const double q = (o.end.distal ? 1.0 : -1.0) * s.flow[v], p = s.node_pressure[o.end.distal ? net.to[v] : net.from[v]];
    if (o.capacitor >= 0) state_.capacitor(o.capacitor) = p - o.outlet.r1 * q;
    o.rest_area = end_law(v, o.end.distal).area(p);
    o.rest_flow = s.flow[v];
  }
}

void PulseSolver::start_from_periodic(const PeriodicInstant& instant) {
  // The steady start has set what else a start needs (the reflection outlets' rest states);
  // this replaces the state with the periodic one at t = time_ (the instant's).
  const Network& net = net_;
  const std::size_t n = net.vessel_count();
  const LinearPeriodic& periodic = instant.along;  // the 1D vessels' whole state
  lumped_.start(instant.node_pressure, instant.middle_flow);
  for (std::size_t v = 0; v < n; ++v) {
    if (zero_d_[v]) continue;
    auto pressure = [&](double x) { return periodic.pressure_at(v, x, time_); };
    if (is_tapered(v)) {
      const VesselTaper& taper = tapers_[static_cast<std::size_t>(taper_of_[v])];
      project_along(v, [&](double x) { return taper.at(x).area(pressure(x)); }, state_.area);
    } else {
      project_along(v, [&](double x) { return laws_[v].area(pressure(x)); }, state_.area);
    }
    project_along(v, [&](double x) { return periodic.flow_at(v, x, time_); }, state_.flow);
  }
  for (const auto& o : boundaries_.outlets) {
    if (o.capacitor < 0) continue;
    const auto v = static_cast<std::size_t>(o.end.vessel);
    const double s = o.end.distal ? 1.0 : 0.0;
    const double q = (o.end.distal ? 1.0 : -1.0) * periodic.flow_at(v, s, time_);
    state_.capacitor(o.capacitor) = periodic.pressure_at(v, s, time_) - o.outlet.r1 * q;
  }
}

bool PulseSolver::take_lead_start(bool started, const std::optional<PeriodicInstant>& instant) {
  // The lead's outcome, then what its start_from_periodic set: the 0D system's start (its
  // nodes' pressures and vessels' flows, every one's: each rank takes its own and its ghosts')
  // and the 1D vessels' coefficients and capacitors (every rank holds every 1D vessel's rows).
  std::vector<double> outcome{started ? 1.0 : 0.0};
  from_lead_(outcome);
  if (outcome[0] == 0) return false;
  std::vector<double> node_pressure = leads() ? instant->node_pressure : std::vector<double>();
  std::vector<double> middle_flow = leads() ? instant->middle_flow : std::vector<double>();
  from_lead_(node_pressure);
  from_lead_(middle_flow);
  if (!leads()) lumped_.start(node_pressure, middle_flow);
  auto take = [&](double* data, Eigen::Index size) {
    std::vector<double> values(data, data + size);
    from_lead_(values);
    if (values.size() != static_cast<std::size_t>(size))  // every rank lays out every 1D element alike
      throw std::logic_error("PulseSolver::take_lead_start: the lead's 1D state has another size");
    std::copy(values.begin(), values.end(), data);
  };
  take(state_.area.data(), state_.area.size());
  take(state_.flow.data(), state_.flow.size());
  take(state_.capacitor.data(), state_.capacitor.size());
  return true;
}

void PulseSolver::start_from(const PulseSolver& other) {
  if (&other.net_ != &net_ || other.zero_d_ != zero_d_ || other.elements_per_vessel_ != elements_per_vessel_ ||
      other.boundaries_.outlets.size() != boundaries_.outlets.size())
    throw std::invalid_argument("PulseSolver::start_from: a solver of another network or other models");
  lumped_.start_from(other.lumped_);
  for (std::size_t v = 0; v < net_.vessel_count(); ++v) {
    if (zero_d_[v]) continue;
    project_along(v, [&](double x) { return other.area_at(v, x); }, state_.area);
    project_along(v, [&](double x) { return other.flow_at(v, x); }, state_.flow);
  }
  for (const auto& o : boundaries_.outlets)
    if (o.capacitor >= 0) state_.capacitor(o.capacitor) = other.state_.capacitor(o.capacitor);
  restart_clock();
  have_previous_rate_ = false;  // the multistep history starts again
  // The coupled ends' first linearisation needs their end states (as after any start).
  if (!coupling_ranks_.empty()) share_coupling_nodes();
  if (!boundaries_.coupled.empty() && one_d_here_) evaluate(time_, state_, rate_);
  if (one_d_cut_) settle_failures();
}

void PulseSolver::set_viscosity_factors(std::span<const double> per_vessel) {
  viscosity_factor_.assign(per_vessel.begin(), per_vessel.end());
  lumped_.set_viscosity_factors(viscosity_factor_);
  if (viscosity_factor_.empty()) {
    element_viscosity_factor_.resize(0);
    return;
  }
  element_viscosity_factor_.resize(static_cast<Eigen::Index>(element_vessel_.size()));
  for (std::size_t el = 0; el < element_vessel_.size(); ++el)
    element_viscosity_factor_(static_cast<Eigen::Index>(el)) = viscosity_factor_[static_cast<std::size_t>(element_vessel_[el])];
}

void PulseSolver::set_viscosity_factor(std::size_t vessel, double factor) {
  if (viscosity_factor_.empty()) set_viscosity_factors(std::vector<double>(net_.vessel_count(), 1.0));
  viscosity_factor_[vessel] = factor;
  if (zero_d_[vessel]) {
    lumped_.set_viscosity_factor(lumped_.vessel_index(vessel), factor);
    return;
  }
  for (auto el = first_element(vessel), end = end_element(vessel); el < end; ++el) element_viscosity_factor_(el) = factor;
}

void PulseSolver::track_face_volumes() {
  const Eigen::Index elements = state_.area.rows();
  for (PulseState* s : {&state_, &rate_, &previous_rate_, &stage_[0], &stage_[1], &stage_[2], &stage_[3]})
    if (s->area.rows() == elements) s->faces.setZero(elements);
  lumped_.track_passed_volumes();
  tracking_faces_ = true;
}

}  // namespace hemotree
