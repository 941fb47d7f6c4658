#include "pulse/pulse_solver.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <sstream>

#include <omp.h>

#include "core/errors.hpp"
#include "core/parallel_errors.hpp"
#include "formats/connected_parts.hpp"
#include "physics/poiseuille.hpp"
#include "physics/wall_law.hpp"
#include "pulse/solution_breakdown.hpp"
#include "pulse/stability_limit.hpp"
#include "steady/steady_flow.hpp"

namespace hemotree {

void PulseState::set_zero_like(const PulseState& other) {
  area.setZero(other.area.rows(), other.area.cols());
  flow.setZero(other.flow.rows(), other.flow.cols());
  capacitor.setZero(other.capacitor.size());
  exchanged.setZero();
  coupled.setZero(other.coupled.size());
  boundary.setZero(other.boundary.size());
  faces.setZero(other.faces.size());
}

void PulseState::add_scaled(double factor, const PulseState& other) {
  area += factor * other.area;
  flow += factor * other.flow;
  capacitor += factor * other.capacitor;
  exchanged += factor * other.exchanged;
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

PulseSolver::PulseSolver(const Network& net, const SolverOptions& options)
    : net_(net), blood_(effective_blood(net, options)), viscosity_(blood_),
      scheme_(options.scheme) {
  if (options.degree < 0 && options.degree != SolverOptions::automatic)
    throw InputError("--degree must be at least 0");
  if (options.elements < 1) throw InputError("--elements must be at least 1");
  if (options.threads < 1) throw InputError("--threads must be at least 1");
  threads_ = options.threads;
  friction_k_ = friction_coefficient(blood_.alpha);
  const std::size_t n = net.vessel_count();

  // Each vessel's tube law: given directly, or from its wall by the thin/thick model.
  laws_.resize(n);
  for (std::size_t v = 0; v < n; ++v) {
    const std::string name = "vessel " + std::to_string(net.id[v]);
    VesselLaw& law = laws_[v];
    law.density = blood_.density;
    law.alpha = blood_.momentum_alpha();
    if (!net.beta.empty() && !std::isnan(net.beta[v])) {
      law.beta = net.beta[v];
      law.reference_area = std::numbers::pi / 4 * net.diameter[v] * net.diameter[v];
      law.reference_pressure = net.reference_pressure[v];
    } else {
      if (std::isnan(net.wall_thickness[v]) || std::isnan(net.youngs_modulus[v]))
        throw InputError(name + ": needs wall_thickness and youngs_modulus (or beta and reference_pressure)");
      const TubeLaw t = tube_law({net.diameter[v], net.wall_thickness[v], net.youngs_modulus[v]},
                                 options.external_pressure, options.thick_wall_ratio);
      law.beta = t.beta;
      law.reference_area = t.reference_area;
      law.reference_pressure = t.reference_pressure;
    }
    if (net.is_tapered(v)) {
      // The law along the vessel (vessel_equations.hpp): the wall's h and E, or the given
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
  run_outlets_ = run_outlets(run_boundaries(net));
  choose_models(options);
  lumped_ = LumpedVessels(net, laws_, viscosity_, blood_, zero_d_, taper_of_, tapers_);
  lumped_.set_passes(options.lumped_passes);
  lumped_.set_threads(threads_);

  // The steady Poiseuille solution, where the network has one (not with reflection outlets):
  // the degrees follow its pressure profiles, and the run starts from it.
  std::optional<SteadyFlow> steady;
  // (A network with node boundaries takes their means; a tree, its inlet's.)
  try {
    steady = solve_distended_steady_flow(net, blood_, laws_, viscosity_, net.inlet ? net.inlet->waveform.mean_value() : 0.0,
                                         &steady_resistance_);
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
  choose_degrees_and_elements(options, steady ? &*steady : nullptr);
  boundaries_ = build_boundaries(net, first_element_, elements_per_vessel_, zero_d_);
  // The steady solve's rule (docs/network-format.md), once the boundaries' own form is checked:
  // a part with flow boundaries only has no pressure level, and a run from rest over it was
  // called complete (hostile-inputs 05), or failed deep in the 0D solve.
  if (const std::string refusal = pressure_reference_refusal(net, boundaries_.list); !refusal.empty())
    throw InputError(refusal);
  if (steady) {
    // A pressure boundary counts as "in" or "out" by its steady flow.
    std::vector<double> inflow(net.node_count(), 0.0);
    for (std::size_t v = 0; v < n; ++v) {
      inflow[static_cast<std::size_t>(net.from[v])] += steady->flow[v];
      inflow[static_cast<std::size_t>(net.to[v])] -= steady->flow[v];
    }
    for (std::size_t i = 0; i < boundaries_.list.size(); ++i)
      if (boundaries_.list[i].type == BoundaryType::pressure)
        boundaries_.entering[i] = inflow[static_cast<std::size_t>(boundaries_.list[i].node)] >= 0;
  }
  lumped_.set_entering(boundaries_.entering);
  lumped_inflow_.assign(lumped_.inflow_boundaries().size(), 0.0);
  lumped_held_.assign(lumped_.held_boundaries().size(), 0.0);
  for (const auto& c : boundaries_.coupled) coupled_node_.push_back(lumped_.node_of(c.node));
  {
    std::vector<std::int32_t> nodes = coupled_node_;
    std::sort(nodes.begin(), nodes.end());
    nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
    for (const std::int32_t node : coupled_node_)
      coupled_slot_.push_back(static_cast<std::int32_t>(std::lower_bound(nodes.begin(), nodes.end(), node) - nodes.begin()));
    coupled_inflow_.assign(nodes.size(), 0.0);
    lumped_.set_coupling_nodes(std::move(nodes));
  }
  held_end_flow_.assign(boundaries_.coupled.size(), 0.0);
  coupled_volume_ = coupled_inflow_;

  const auto rows = static_cast<Eigen::Index>(element_vessel_.size());
  Eigen::Index points = 0;
  for (const DegreeBlock& b : blocks_) points = std::max<Eigen::Index>(points, bases_[b.degree].points);
  const Eigen::Index modes = max_degree() + 1;
  state_.area.setZero(rows, modes);
  state_.flow.setZero(rows, modes);
  state_.capacitor.setZero(static_cast<Eigen::Index>(boundaries_.capacitors));
  state_.coupled.setZero(static_cast<Eigen::Index>(boundaries_.coupled.size()));
  state_.boundary.setZero(static_cast<Eigen::Index>(boundaries_.list.size()));
  area_q_.resize(rows, points);
  flow_q_.resize(rows, points);
  flux_q_.resize(rows, points);
  source_q_.resize(rows, points);

  compute_rest_correction();
  started_from_steady_ = options.steady_start && steady;
  if (started_from_steady_) start_from_steady_flow(*steady);
  else start_at_rest();
  choose_time_step(options);
  stable_1d_ = dt_;
  stable_dt_ = dt_;
  stable_dt_reason_ = dt_reason_;
  if (!lumped_.empty()) {
    // The 0D step follows the pulse (it has no stability limit); the 1D vessels take as
    // many substeps of at most their own limit as fit in it.
    const double target = options.lumped_step * period_;
    const double substeps = std::isfinite(stable_1d_) ? std::max(1.0, std::floor(target / stable_1d_)) : 1.0;
    dt_ = std::isfinite(stable_1d_) ? std::min(target, substeps * stable_1d_) : target;
    std::ostringstream why;
    why << "0D step of " << options.lumped_step << " of the period";
    if (std::isfinite(stable_1d_)) why << ", " << substeps << " 1D substeps set by the " << dt_reason_;
    dt_reason_ = why.str();
    // The implicit 0D step is stable at any length, but not accurate: BDF2 follows the pulse
    // only at steps of about --lumped-step of the period (a --dt of one step a cycle stored
    // 16 % of the inflow and was called complete). The 1D substeps keep their own limit.
    stable_dt_ = target;
    std::ostringstream limit;
    limit << "--lumped-step " << options.lumped_step << " of the period: BDF2 is stable at any step but follows "
             "the pulse only at steps like it";
    stable_dt_reason_ = limit.str();
  }
  set_time_step(dt_);
  if (options.dt > 0) {
    set_time_step(options.dt);
    dt_reason_ = "given by --dt";
  }
  // The coupled ends' first linearisation needs their end states.
  if (!boundaries_.coupled.empty()) evaluate(time_, state_, rate_);
}

void PulseSolver::set_time_step(double dt) {
  dt_ = dt;
  substeps_ = lumped_.empty() || !std::isfinite(stable_1d_)
                  ? 1
                  : static_cast<int>(std::max(1.0, std::ceil(dt / stable_1d_ - 1e-9)));
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
  for (const NodeBoundary& b : run_boundaries(net_))
    if (b.type == BoundaryType::reflection) reflecting_node[static_cast<std::size_t>(b.node)] = true;
  for (std::size_t v = 0; v < n; ++v)
    reflecting[v] = reflecting_node[static_cast<std::size_t>(net_.from[v])] || reflecting_node[static_cast<std::size_t>(net_.to[v])];
  const double period = period_, omega = 2 * std::numbers::pi / period;
  for (std::size_t v = 0; v < n; ++v) {
    const VesselLaw& law = laws_[v];
    const double area = law.reference_area, length = net_.length[v];
    double transit = length / law.wave_speed(area);
    double compliance = length * 2 * std::sqrt(area) / law.beta;
    double resistance = friction_k_ * viscosity_(area) * length / (area * area);
    if (is_tapered(v)) {
      // The same integrals along the vessel: int dx / c, int dA/dp dx, int k mu / A^2 dx.
      const VesselTaper& taper = tapers_[static_cast<std::size_t>(taper_of_[v])];
      transit = compliance = 0;
      for (std::size_t i = 0; i < taper_rule_nodes.size(); ++i) {
        const VesselLaw at = taper.at(taper_rule_nodes[i]);
        const double a = taper.rest_area(taper_rule_nodes[i]);
        transit += taper_rule_weights[i] * length / at.wave_speed(a);
        compliance += taper_rule_weights[i] * length * 2 * std::sqrt(a) / at.beta;
      }
      resistance = tapered_poiseuille_resistance(
          [&](double d) { return viscosity_(std::numbers::pi / 4 * d * d); }, length, taper.d0, taper.d1, blood_.alpha);
    }
    zero_d_[v] = !reflecting[v] && transit < options.lumped_transit * period &&
                 omega * resistance * compliance < options.lumped_rc;
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
    vessel_degree_ = choose_degrees(transit, linear_error, period, options.degree_rule,
                                    scheme_ == TimeScheme::runge_kutta4 ? TimeScheme::runge_kutta4
                                                                        : TimeScheme::adams_bashforth2);
  } else {
    vessel_degree_.assign(n, options.degree);
  }
  std::size_t one_d = 0;
  for (std::size_t v = 0; v < n; ++v) {
    if (zero_d_[v]) vessel_degree_[v] = -1;
    else ++one_d;
    // A tapered vessel's rest lumen pi D(x)^2 / 4 is quadratic in x: degree 2 holds it
    // exactly, and with it the rest state (well-balanced, docs/solver.md §1a).
    if (!zero_d_[v] && is_tapered(v)) vessel_degree_[v] = std::max(vessel_degree_[v], 2);
  }
  const int top = std::max(0, n == 0 ? 0 : *std::max_element(vessel_degree_.begin(), vessel_degree_.end()));
  bases_.assign(static_cast<std::size_t>(top) + 1, ModalBasis{});
  first_element_.assign(n, -1);
  element_vessel_.resize(one_d * static_cast<std::size_t>(e));
  half_length_.resize(static_cast<Eigen::Index>(element_vessel_.size()));
  element_beta_.resize(half_length_.size());
  blocks_.clear();
  one_d_vessels_.clear();
  std::int32_t next = 0;
  for (int p = 0; p <= top; ++p) {
    const std::int32_t first = next;
    for (std::size_t v = 0; v < n; ++v) {
      if (vessel_degree_[v] != p) continue;
      first_element_[v] = next;
      for (int k = 0; k < e; ++k, ++next) {
        element_vessel_[static_cast<std::size_t>(next)] = static_cast<std::int32_t>(v);
        half_length_(next) = net_.length[v] / (2.0 * e);
        element_beta_(next) = laws_[v].beta;
      }
    }
    if (next == first) continue;
    for (std::int32_t el = first; el < next; el += e) one_d_vessels_.push_back(element_vessel_[static_cast<std::size_t>(el)]);
    bases_[static_cast<std::size_t>(p)] = modal_basis(p, options.quadrature_points);
    blocks_.push_back({p, first, next - first});
  }
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
  for (const DegreeBlock& b : blocks_) points = std::max<Eigen::Index>(points, bases_[static_cast<std::size_t>(b.degree)].points);
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
    const int k = el - first_element_[v];
    for (Eigen::Index q = 0; q < basis.points; ++q) {
      const double s = (k + 0.5 * (basis.rule.nodes(q) + 1)) / e;
      taper_beta_(row, q) = taper.at(s).beta;
      taper.source_coefficients(s, taper_g1_(row, q), taper_g0_(row, q));
    }
    taper_right_law_.push_back(taper.at(static_cast<double>(k + 1) / e));
  }
}

VesselLaw PulseSolver::law_at(std::size_t vessel, double x) const {
  if (!is_tapered(vessel)) return laws_[vessel];
  return tapers_[static_cast<std::size_t>(taper_of_[vessel])].at(std::clamp(x, 0.0, 1.0));
}

// ---- initial states --------------------------------------------------------------------

void PulseSolver::start_at_rest() {
  // Every vessel at its reference area and no flow: p = p_ref.
  for (std::size_t v = 0; v < net_.vessel_count(); ++v) {
    if (is_tapered(v) && !zero_d_[v]) {
      // A tapered vessel rests at its measured lumen pi D(x)^2 / 4, where the pressure is the
      // same all along (vessel_equations.hpp): quadratic in x, projected exactly at degree 2.
      const VesselTaper& taper = tapers_[static_cast<std::size_t>(taper_of_[v])];
      project_along(v, [&](double x) { return taper.rest_area(x); }, state_.area);
      continue;
    }
    for (auto el = first_element_[v]; el < end_element(v); ++el)
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
    coefficients.row(first_element_[v] + k).head(basis.degree + 1) = (basis.projection * values).transpose();
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
      flux(q) = taper_beta_(r, q) * a_q(q) * root / (3 * rho);
      source(q) = a_q(q) * (taper_g1_(r, q) * root + taper_g0_(r, q));
    }
    const int k = el - first_element_[v];
    const VesselLaw left = taper.at(static_cast<double>(k) / e), right = taper.at(static_cast<double>(k + 1) / e);
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
      for (auto k = 0; k < e; ++k) state_.flow(first_element_[v] + k, 0) = s.flow[v];
      continue;
    }
    for (auto k = 0; k < e; ++k) {
      // Pressure falls linearly along the vessel; project A(p(x)) onto the modes.
      Eigen::VectorXd a(points);
      for (Eigen::Index q = 0; q < points; ++q) {
        const double x = (k + 0.5 * (basis.rule.nodes(q) + 1)) / e;
        a(q) = laws_[v].area(p0 + (p1 - p0) * x);
      }
      const auto el = first_element_[v] + k;
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

// ---- time step ---------------------------------------------------------------------------

void PulseSolver::choose_time_step(const SolverOptions& options) {
  // Waves: dt <= cfl nu_max(p) h / lambda_max, with nu_max from the Bloch analysis of the DG
  // operator (0.50 at p = 1 down to 0.0133 at p = 7 for AB2); friction (explicit schemes):
  // dt <= safety / (k mu / (rho A)).
  std::vector<double> courant(bases_.size(), 0.0);
  for (const DegreeBlock& b : blocks_)
    courant[static_cast<std::size_t>(b.degree)] =
        options.cfl * courant_limit(b.degree, scheme_ == TimeScheme::runge_kutta4 ? TimeScheme::runge_kutta4
                                                                                  : TimeScheme::adams_bashforth2);
  double wave = std::numeric_limits<double>::infinity(), friction = wave;
  std::size_t wave_vessel = 0, friction_vessel = 0;
  for (std::size_t v = 0; v < net_.vessel_count(); ++v) {
    if (zero_d_[v]) continue;
    const VesselLaw& law = laws_[v];
    const auto el = first_element_[v];
    const double a = state_.area(el, 0), q = state_.flow(el, 0);
    const double h = 2 * half_length_(el);
    double lambda = std::max(std::abs(law.lambda_forward(a, q)), std::abs(law.lambda_backward(a, q)));
    if (is_tapered(v)) {
      // The speeds change along the vessel: the largest at the ends of its elements.
      const int degree = vessel_degree_[v];
      for (auto k = first_element_[v]; k < end_element(v); ++k) {
        const int j = k - first_element_[v];
        for (const int side : {0, 1}) {
          const VesselLaw at = law_at(v, static_cast<double>(j + side) / elements_per_vessel_);
          double ak = 0, qk = 0;
          for (int m = 0; m <= degree; ++m) {
            const double sign = side == 0 && m % 2 == 1 ? -1.0 : 1.0;  // P_m(-1) = (-1)^m
            ak += sign * state_.area(k, m);
            qk += sign * state_.flow(k, m);
          }
          lambda = std::max({lambda, std::abs(at.lambda_forward(ak, qk)), std::abs(at.lambda_backward(ak, qk))});
        }
      }
    }
    const double dt_wave = courant[static_cast<std::size_t>(vessel_degree_[v])] * h / lambda;
    if (dt_wave < wave) {
      wave = dt_wave;
      wave_vessel = v;
    }
    const double rate = friction_k_ * viscosity_(a) / (blood_.density * a);
    const double stability = scheme_ == TimeScheme::runge_kutta4 ? 2.78 : 1.0;
    const double dt_friction = scheme_ == TimeScheme::exponential_ab2
                                   ? std::numeric_limits<double>::infinity()
                                   : options.friction_safety * stability / rate;
    if (dt_friction < friction) {
      friction = dt_friction;
      friction_vessel = v;
    }
  }
  // The capacitor of an RCR outlet relaxes at the rate (1/R1 + 1/R2)/C at most (R1 in
  // series with the vessel's impedance is slower), and every scheme here steps it explicitly.
  double capacitor = std::numeric_limits<double>::infinity();
  std::size_t capacitor_vessel = 0;
  for (const auto& o : boundaries_.outlets) {
    if (o.capacitor < 0) continue;
    const double rate = (1 / o.outlet.r1 + 1 / o.outlet.r2) / o.outlet.c;
    const double stability = scheme_ == TimeScheme::runge_kutta4 ? 2.78 : 1.0;
    const double dt_capacitor = options.friction_safety * stability / rate;
    if (dt_capacitor < capacitor) {
      capacitor = dt_capacitor;
      capacitor_vessel = static_cast<std::size_t>(o.end.vessel);
    }
  }
  std::ostringstream why;
  dt_ = std::min({wave, friction, capacitor});
  if (!std::isfinite(dt_)) why << "no 1D vessels";
  else if (dt_ == wave) why << "wave speed (CFL) in vessel " << net_.id[wave_vessel];
  else if (dt_ == friction) why << "friction stiffness in vessel " << net_.id[friction_vessel];
  else why << "RCR outlet capacitor of vessel " << net_.id[capacitor_vessel];
  dt_reason_ = why.str();
}

namespace {
// e^z, phi1(z) = (e^z - 1)/z and phi2(z) = (e^z - 1 - z)/z^2, by series near 0 where the
// formulas cancel.
void phi_functions(double z, double& e, double& phi1, double& phi2) {
  e = std::exp(z);
  if (std::abs(z) < 1e-3) {
    phi1 = 1 + z / 2 + z * z / 6 + z * z * z / 24;
    phi2 = 0.5 + z / 6 + z * z / 24 + z * z * z / 120;
    return;
  }
  phi1 = (e - 1) / z;
  phi2 = (e - 1 - z) / (z * z);
}
}  // namespace

void PulseSolver::step_exponential(double h) {
  // ETD2 (Cox & Matthews 2002): Q+ = e^z Q + h (phi1(z) N + phi2(z) (N - N_prev)), z = -r h,
  // with N = rate + r Q the non-stiff part; A and the capacitors (r = 0) take plain AB2.
  // Both N are taken with this step's r (N_prev = rate_prev + r Q_prev): with the previous
  // step's r the scheme falls to first order wherever the area, and so r, pulsates.
  evaluate(time_, state_, rate_);
  if (!have_previous_rate_) {
    previous_rate_ = rate_;
    previous_flow_ = state_.flow;
    have_previous_rate_ = true;
  }
  const Eigen::Index elements = state_.flow.rows();
  decay_.resize(elements);
  next_flow_.resize(elements);
  phi1_.resize(elements);
  phi2_.resize(elements);
  for (Eigen::Index el = 0; el < elements; ++el) phi_functions(-friction_rate_(el) * h, decay_(el), phi1_(el), phi2_(el));
  // Column by column (the storage order), over each degree's block of rows.
  for (const DegreeBlock& b : blocks_)
    for (Eigen::Index j = 0; j <= b.degree; ++j) {
      const auto r = friction_rate_.segment(b.first, b.count).array();
      auto q = state_.flow.col(j).segment(b.first, b.count).array();
      auto q_before = previous_flow_.col(j).segment(b.first, b.count).array();
      const auto n_now = rate_.flow.col(j).segment(b.first, b.count).array() + r * q;
      const auto n_before = previous_rate_.flow.col(j).segment(b.first, b.count).array() + r * q_before;
      auto next = next_flow_.segment(b.first, b.count).array();  // scratch: no allocation per step
      next = decay_.segment(b.first, b.count).array() * q +
             h * (phi1_.segment(b.first, b.count).array() * n_now +
                  phi2_.segment(b.first, b.count).array() * (n_now - n_before));
      q_before = q;
      q = next;
    }
  state_.area += h * (1.5 * rate_.area - 0.5 * previous_rate_.area);
  state_.capacitor += h * (1.5 * rate_.capacitor - 0.5 * previous_rate_.capacitor);
  state_.exchanged += h * (1.5 * rate_.exchanged - 0.5 * previous_rate_.exchanged);
  state_.coupled += h * (1.5 * rate_.coupled - 0.5 * previous_rate_.coupled);
  state_.boundary += h * (1.5 * rate_.boundary - 0.5 * previous_rate_.boundary);
  state_.faces += h * (1.5 * rate_.faces - 0.5 * previous_rate_.faces);
  std::swap(previous_rate_, rate_);
}

void PulseSolver::step() {
  if (lumped_.empty()) {
    step_1d(dt_);
    time_ += dt_;
  } else {
    step_coupled();
  }
  ++steps_;
}

void PulseSolver::step_coupled() {
  // The 0D vessels step first with the coupled ends' inflows held at their last values; the
  // 1D ends then see each node's pressure move to the prediction, plus the node's own
  // response to their departure from the held inflow: a Robin condition. Without it the
  // coupling is explicit, and unstable once the step exceeds the node's C / Y; with the
  // response of BDF2 (Z = (K^-1)_ii) it broke down at 4 substeps, with 3/2 Z, the backward
  // Euler response of a compliance-dominated node, it ran at 41 (docs/solver.md §10).
  std::fill(coupled_inflow_.begin(), coupled_inflow_.end(), 0.0);
  for (std::size_t k = 0; k < boundaries_.coupled.size(); ++k) {
    const VesselEnd& end = boundaries_.coupled[k].end;
    const EndState& u = boundaries_.end_state[2 * static_cast<std::size_t>(end.vessel) + (end.distal ? 1 : 0)];
    held_end_flow_[k] = end.distal ? u.flow : -u.flow;
    coupled_inflow_[static_cast<std::size_t>(coupled_slot_[k])] += held_end_flow_[k];
  }
  step_start_ = time_;
  const double t1 = time_ + dt_;
  // The boundary flows and pressures at the 0D vessels' nodes, at the step's end.
  for (std::size_t j = 0; j < lumped_inflow_.size(); ++j)
    lumped_inflow_[j] = boundaries_.list[static_cast<std::size_t>(lumped_.inflow_boundaries()[j])].waveform(t1);
  for (std::size_t j = 0; j < lumped_held_.size(); ++j)
    lumped_held_[j] = boundaries_.list[static_cast<std::size_t>(lumped_.held_boundaries()[j])].waveform(t1);
  lumped_.predict(dt_, coupled_inflow_, lumped_inflow_, lumped_held_);
  // The 1D vessels follow, seeing the coupling nodes' pressures move linearly to the prediction.
  if (element_count() > 0) {
    const Eigen::VectorXd before = state_.coupled;
    const double h = dt_ / substeps_;
    for (int k = 0; k < substeps_; ++k) {
      step_1d(h);
      time_ = step_start_ + (k + 1) * h;
    }
    std::fill(coupled_volume_.begin(), coupled_volume_.end(), 0.0);
    for (std::size_t k = 0; k < boundaries_.coupled.size(); ++k)
      coupled_volume_[static_cast<std::size_t>(coupled_slot_[k])] +=
          state_.coupled(static_cast<Eigen::Index>(k)) - before(static_cast<Eigen::Index>(k));
  }
  // The 0D vessels receive exactly what the 1D ends let through: mass to round-off.
  lumped_.complete(coupled_volume_, state_.exchanged(0), state_.exchanged(1),
                   std::span<double>(state_.boundary.data(), static_cast<std::size_t>(state_.boundary.size())));
  time_ = t1;
}

void PulseSolver::step_1d(double dt) {
  if (scheme_ == TimeScheme::exponential_ab2) {
    step_exponential(dt);
  } else if (scheme_ == TimeScheme::runge_kutta4) {
    // Classical fourth-order Runge-Kutta.
    evaluate(time_, state_, stage_[0]);
    PulseState y = state_;
    y.add_scaled(0.5 * dt, stage_[0]);
    evaluate(time_ + 0.5 * dt, y, stage_[1]);
    y = state_;
    y.add_scaled(0.5 * dt, stage_[1]);
    evaluate(time_ + 0.5 * dt, y, stage_[2]);
    y = state_;
    y.add_scaled(dt, stage_[2]);
    evaluate(time_ + dt, y, stage_[3]);
    state_.add_scaled(dt / 6, stage_[0]);
    state_.add_scaled(dt / 3, stage_[1]);
    state_.add_scaled(dt / 3, stage_[2]);
    state_.add_scaled(dt / 6, stage_[3]);
  } else {
    // Second-order Adams-Bashforth (the paper's); its first step is Heun's, second order too.
    evaluate(time_, state_, rate_);
    if (!have_previous_rate_) {
      PulseState y = state_;
      y.add_scaled(dt, rate_);
      evaluate(time_ + dt, y, stage_[0]);
      state_.add_scaled(0.5 * dt, rate_);
      state_.add_scaled(0.5 * dt, stage_[0]);
      have_previous_rate_ = true;
    } else {
      state_.add_scaled(1.5 * dt, rate_);
      state_.add_scaled(-0.5 * dt, previous_rate_);
    }
    std::swap(previous_rate_, rate_);
  }
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
  for (auto el = first_element_[vessel]; el < end_element(vessel); ++el) element_viscosity_factor_(el) = factor;
}

void PulseSolver::track_face_volumes() {
  const Eigen::Index elements = state_.area.rows();
  for (PulseState* s : {&state_, &rate_, &previous_rate_, &stage_[0], &stage_[1], &stage_[2], &stage_[3]})
    if (s->area.rows() == elements) s->faces.setZero(elements);
  lumped_.track_passed_volumes();
  tracking_faces_ = true;
}

// ---- evaluation --------------------------------------------------------------------------

void PulseSolver::locate(std::size_t vessel, double x, std::size_t& element, double& xi) const {
  const auto first = first_element_[vessel], count = elements_per_vessel_;
  const double s = std::clamp(x, 0.0, 1.0) * count;
  const auto k = std::min(static_cast<std::int32_t>(s), count - 1);
  element = static_cast<std::size_t>(first + k);
  xi = 2 * (s - k) - 1;
}

double PulseSolver::evaluate_modes(const Eigen::MatrixXd& c, std::size_t element, double xi) const {
  double value = 0;
  const int degree = vessel_degree_[static_cast<std::size_t>(element_vessel_[element])];
  for (int j = 0; j <= degree; ++j) value += c(static_cast<Eigen::Index>(element), j) * legendre(j, xi);
  return value;
}

double PulseSolver::area_at(std::size_t vessel, double x) const {
  if (zero_d_[vessel]) return law_at(vessel, x).area(pressure_at(vessel, x));
  std::size_t el;
  double xi;
  locate(vessel, x, el, xi);
  return evaluate_modes(state_.area, el, xi);
}

double PulseSolver::flow_at(std::size_t vessel, double x) const {
  if (zero_d_[vessel]) return lumped_.flow(lumped_.vessel_index(vessel));
  std::size_t el;
  double xi;
  locate(vessel, x, el, xi);
  return evaluate_modes(state_.flow, el, xi);
}

double PulseSolver::pressure_at(std::size_t vessel, double x) const {
  if (zero_d_[vessel]) return lumped_.pressure_at(lumped_.vessel_index(vessel), std::clamp(x, 0.0, 1.0));
  return law_at(vessel, x).pressure(area_at(vessel, x));
}

double PulseSolver::viscosity_at(std::size_t vessel, double x) const {
  return viscosity(vessel, area_at(vessel, x));
}

void PulseSolver::sample_all(double x, std::vector<double>& area, std::vector<double>& flow,
                             std::vector<double>* pressure, bool zero_d) const {
  const std::size_t n = net_.vessel_count();
  area.resize(n);
  flow.resize(n);
  if (pressure) pressure->resize(n);
  if (n == 0) return;
  // The same element k and point xi in every vessel (locate's arithmetic).
  const double s = std::clamp(x, 0.0, 1.0) * elements_per_vessel_;
  const auto k = std::min(static_cast<std::int32_t>(s), elements_per_vessel_ - 1);
  const double xi = 2 * (s - k) - 1;
  std::array<double, 32> phi;  // degrees are at most 30
  for (std::size_t j = 0; j <= static_cast<std::size_t>(max_degree()); ++j) phi[j] = legendre(static_cast<int>(j), xi);
  // The 0D vessels from their own state, then the 1D ones (the first of each one's elements
  // names it).
  if (zero_d)
    lumped_.sample(std::clamp(x, 0.0, 1.0), area, flow, pressure ? std::span<double>(*pressure) : std::span<double>(), threads_);
  const auto one_d = static_cast<std::int64_t>(one_d_vessels_.size());
#pragma omp parallel for schedule(static) num_threads(threads_) if (threads_ > 1)
  for (std::int64_t j = 0; j < one_d; ++j) {
    const auto v = static_cast<std::size_t>(one_d_vessels_[static_cast<std::size_t>(j)]);
    const Eigen::Index el = first_element_[v] + k;
    double a = 0, q = 0;
    for (int j = 0; j <= vessel_degree_[v]; ++j) {
      a += state_.area(el, j) * phi[static_cast<std::size_t>(j)];
      q += state_.flow(el, j) * phi[static_cast<std::size_t>(j)];
    }
    area[v] = a;
    flow[v] = q;
    if (pressure) (*pressure)[v] = is_tapered(v) ? law_at(v, x).pressure(a) : laws_[v].pressure(a);
  }
}

double PulseSolver::mean_flow(std::size_t vessel) const {
  if (zero_d_[vessel]) return lumped_.flow(lumped_.vessel_index(vessel));
  double sum = 0;
  for (auto el = first_element_[vessel]; el < end_element(vessel); ++el) sum += state_.flow(el, 0);
  return sum / elements_per_vessel_;
}

double PulseSolver::network_volume() const {
  // The 1D vessels' volumes and what the 0D scheme conserves (lumped_vessels.hpp).
  double volume = lumped_.stored_volume();
  for (std::size_t v = 0; v < net_.vessel_count(); ++v)
    for (auto el = first_element_[v]; el < end_element(v); ++el) volume += 2 * half_length_(el) * state_.area(el, 0);
  return volume;
}

void PulseSolver::check_solution() const {
  lumped_.check(time_);
  for (Eigen::Index el = 0; el < state_.area.rows(); ++el)
    if (!(state_.area(el, 0) > 0) || !state_.area.row(el).allFinite() || !state_.flow.row(el).allFinite())
      throw SolutionBreakdown(net_.id[static_cast<std::size_t>(element_vessel_[el])], time_);
}

}  // namespace hemotree
