// The time step and the schemes that take it (docs/solver.md §5, §10): the step, decided here
// alone (choose_time_step: the 1D stability limits, the 0D step and the 1D substeps in it, or
// the step given, and the coupling passes that cost least; the run room only shortens the
// step to a whole number per cycle); ETD2 (exponential in the friction), AB2 and classical RK4 on the
// 1D vessels' state, each a sequence of DG rates (pulse/dg_rate.cpp); and the 1D-0D step: one
// implicit 0D step of the lumped vessels around the 1D substeps inside it (step_coupled).
#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "core/setting_error.hpp"
#include "pulse/pulse_solver.hpp"
#include "pulse/solution_breakdown.hpp"
#include "pulse/stability_limit.hpp"
#include "pulse/step_cost.hpp"

namespace hemotree {

void PulseSolver::set_time_step(double dt) {
  dt_ = dt;
  substeps_ = lumped_vessels_in_run() == 0 || !std::isfinite(stable_1d_)
                  ? 1
                  : static_cast<int>(std::max(1.0, std::ceil(dt / stable_1d_ - 1e-9)));
}

void PulseSolver::choose_time_step(const SolverOptions& options) {
  choose_stable_step(options);
  stable_1d_ = dt_;
  stable_dt_ = dt_;
  stable_dt_reason_ = dt_reason_;
  if (lumped_vessels_in_run() > 0) {
    // The 0D step follows the pulse (it has no stability limit); the 1D vessels take as
    // many substeps of at most their own limit as fit in it.
    coupling_passes_ = choose_coupling_passes(options);
    const double fraction = options.lumped_step > 0 ? options.lumped_step : step_cost::step_per_coupling_pass * coupling_passes_;
    const double target = fraction * period_;
    const double substeps = std::isfinite(stable_1d_) ? std::max(1.0, std::floor(target / stable_1d_)) : 1.0;
    dt_ = std::isfinite(stable_1d_) ? std::min(target, substeps * stable_1d_) : target;
    std::ostringstream why;
    why << "0D step of " << fraction << " of the period";
    if (coupling_passes_ > 1) why << " in " << coupling_passes_ << " coupling passes";
    if (std::isfinite(stable_1d_)) why << ", " << substeps << " 1D substeps set by the " << dt_reason_;
    dt_reason_ = why.str();
    // The implicit 0D step is stable at any length, but not accurate: BDF2 follows the pulse
    // only at steps of about --lumped-step of the period (a --dt of one step a cycle stored
    // 16 % of the inflow and was called complete). The 1D substeps keep their own limit.
    stable_dt_ = target;
    std::ostringstream limit;
    limit << placeholder("lumped_step") << " " << fraction << " of the period: BDF2 is stable at any step but follows "
             "the pulse only at steps like it";
    stable_dt_reason_ = limit.str();
  }
  set_time_step(dt_);
  if (options.dt > 0) {
    set_time_step(options.dt);
    dt_reason_ = "given by " + placeholder("dt");
  }
}

int PulseSolver::choose_coupling_passes(const SolverOptions& options) const {
  if (boundaries_.coupled.empty() || !std::isfinite(stable_1d_)) return 1;
  if (options.coupling_passes != SolverOptions::automatic) return options.coupling_passes;
  using step_cost::most_coupling_passes, step_cost::step_per_coupling_pass;
  // A step given takes the passes measured for it: one per thousandth of the period begun.
  if (options.lumped_step > 0)
    return std::clamp(static_cast<int>(std::ceil(options.lumped_step / step_per_coupling_pass - 1e-9)), 1,
                      most_coupling_passes);
  // A cycle's 1D substeps, the same work for each pass, against its 0D steps at one pass's step.
  double substep = step_cost::per_step;
  for (const ElementRun& b : blocks_) substep += static_cast<double>(b.count) * step_cost::element_step_seconds(b.degree);
  const double one_d = period_ / stable_1d_ * substep;
  const double zero_d = static_cast<double>(lumped_vessels_in_run()) * step_cost::per_lumped_vessel / step_per_coupling_pass;
  return step_cost::cheapest_coupling_passes(one_d, zero_d, most_coupling_passes);
}

void PulseSolver::choose_stable_step(const SolverOptions& options) {
  // Waves: dt <= cfl nu_max(p) h / lambda_max, with nu_max from the Bloch analysis of the DG
  // operator (0.50 at p = 1 down to 0.0133 at p = 7 for AB2); friction (explicit schemes):
  // dt <= safety / (k mu / (rho A)).
  std::vector<double> courant(bases_.size(), 0.0);
  for (const ElementRun& b : blocks_)
    courant[static_cast<std::size_t>(b.degree)] =
        options.cfl * courant_limit(b.degree, scheme_ == TimeScheme::runge_kutta4 ? TimeScheme::runge_kutta4
                                                                                  : TimeScheme::adams_bashforth2);
  double wave = std::numeric_limits<double>::infinity(), friction = wave;
  std::size_t wave_vessel = 0, friction_vessel = 0;
  for (std::size_t v = 0; v < net_.vessel_count(); ++v) {
    if (zero_d_[v]) continue;
    const auto el = first_element(v);
    const TubeLaw& law = element_law_[static_cast<std::size_t>(el)];
    const double a = state_.area(el, 0), q = state_.flow(el, 0);
    const double h = 2 * half_length_(el);
    double lambda = std::max(std::abs(law.lambda_forward(a, q)), std::abs(law.lambda_backward(a, q)));
    if (is_tapered(v)) {
      // The speeds change along the vessel: the largest at the ends of its elements.
      const int degree = vessel_degree_[v];
      const auto first = first_element(v);
      for (auto k = first, end = end_element(v); k < end; ++k) {
        const int j = k - first;
        for (const int side : {0, 1}) {
          const TubeLaw at = law_at(v, static_cast<double>(j + side) / elements_per_vessel_);
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
  for (const ElementRun& b : runs_)
    for (Eigen::Index el = b.first; el < b.first + b.count; ++el) phi_functions(-friction_rate_(el) * h, decay_(el), phi1_(el), phi2_(el));
  // Column by column (the storage order), over each degree's block of rows.
  for (const ElementRun& b : runs_)
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
  state_.coupled += h * (1.5 * rate_.coupled - 0.5 * previous_rate_.coupled);
  state_.boundary += h * (1.5 * rate_.boundary - 0.5 * previous_rate_.boundary);
  state_.faces += h * (1.5 * rate_.faces - 0.5 * previous_rate_.faces);
  std::swap(previous_rate_, rate_);
}

void PulseSolver::step() { step({}); }

void PulseSolver::step(const std::function<void()>& while_waiting) {
  if (lumped_count_after_release_) throw std::logic_error("PulseSolver::step after release_lumped_state");
  if (!lumped_in_run_) {
    step_1d(dt_);
    if (one_d_cut_) settle_failures();
    time_ += dt_;
  } else {
    step_coupled(while_waiting);
  }
  ++steps_;
}

void PulseSolver::step_coupled(const std::function<void()>& while_waiting) {
  // The 0D vessels step first with the coupled ends' inflows held at their last values; the
  // 1D ends then see each node's pressure move to the prediction, plus the node's own
  // response to their departure from the held inflow: a Robin condition. Without it the
  // coupling is explicit, and unstable once the step exceeds the node's C / Y; with the
  // response of BDF2 (Z = (K^-1)_ii) it broke down at 4 substeps, with 3/2 Z, the backward
  // Euler response of a compliance-dominated node, it ran at 41 (docs/solver.md §10). With
  // several coupling passes the substeps are taken again, each time with the inflows held at
  // the means the pass before let through. Over ranks, a share steps its 0D vessels alone.
  for (std::size_t k = 0; k < boundaries_.coupled.size() && one_d_here_; ++k) {
    const VesselEnd& end = boundaries_.coupled[k].end;
    if (!steps_end(end)) continue;  // another rank's (the 1D vessels spread)
    const EndState& u = boundaries_.state_at(end);
    held_end_flow_[k] = end.distal ? u.flow : -u.flow;
  }
  sum_held_inflows();
  step_start_ = time_;
  const double t1 = time_ + dt_;
  // The boundary flows and pressures at the 0D vessels' nodes, at the step's end.
  for (std::size_t j = 0; j < lumped_inflow_.size(); ++j)
    lumped_inflow_[j] = boundaries_.list.waveform(static_cast<std::size_t>(lumped_.inflow_boundaries()[j]))(t1);
  for (std::size_t j = 0; j < lumped_held_.size(); ++j)
    lumped_held_[j] = boundaries_.list.waveform(static_cast<std::size_t>(lumped_.held_boundaries()[j]))(t1);
  // Spread over ranks, a rank's 0D system is its own (it may have none); a lumen closing on
  // any rank is said on every rank, the least vessel's. A halo's predict has agreed it
  // already (before its solve, which every rank enters): thrown on every rank alike.
  std::int64_t collapsed_vessel = -1;
  try {
    if (steps_lumped()) lumped_.predict(dt_, coupled_inflow_, lumped_inflow_, lumped_held_);
  } catch (const LumpedVessels::CollapsedNode& collapsed) {
    if (!one_d_cut_ || lumped_.halo()) throw SolutionBreakdown(net_.id[static_cast<std::size_t>(collapsed.vessel)], time_);
    collapsed_vessel = collapsed.vessel;
  }
  if (one_d_cut_) {
    constexpr std::int64_t none = std::numeric_limits<std::int64_t>::max();
    if (!lumped_.halo())
      if (const std::int64_t least = least_key_(collapsed_vessel >= 0 ? collapsed_vessel : none); least != none)
        throw SolutionBreakdown(net_.id[static_cast<std::size_t>(least)], time_);
    if (!coupling_ranks_.empty()) share_coupling_nodes();
  }
  if (while_waiting && !one_d_here_) while_waiting();  // a share: the top's rank takes its substeps
  // The 1D vessels follow, seeing the coupling nodes' pressures move linearly to the prediction.
  if (element_count() > 0 && one_d_here_) {
    try {
      take_coupled_substeps();
    } catch (...) {
      // Over ranks every other rank waits for this step's answers: it is refused there too.
      if (lumped_.over_ranks()) lumped_.abandon_step(std::current_exception());
      throw;
    }
  }
  if (one_d_cut_) settle_failures();
  // The 0D vessels receive exactly what the 1D ends let through: mass to round-off.
  if (steps_lumped()) lumped_.complete(coupled_volume_, lumped_boundary_volume_);
  time_ = t1;
}

void PulseSolver::take_coupled_substeps() {
  const Eigen::VectorXd before = state_.coupled;
  if (coupling_passes_ > 1) keep_pass_start();
  for (int pass = 1; pass < coupling_passes_; ++pass) {
    // A pass before the last: its substeps, then the prediction again with each end's
    // inflow held at the mean it let through, and the 1D vessels back at the step's start.
    take_substeps();
    for (std::size_t k = 0; k < boundaries_.coupled.size(); ++k) {
      if (!steps_end(boundaries_.coupled[k].end)) continue;
      const auto i = static_cast<Eigen::Index>(k);
      held_end_flow_[k] = (state_.coupled(i) - before(i)) / dt_;
    }
    sum_held_inflows();
    if (steps_lumped()) lumped_.predict_again(coupled_inflow_);  // collective in a halo
    if (!coupling_ranks_.empty()) share_coupling_nodes();
    return_to_pass_start();
  }
  take_substeps();
  if (!coupling_ranks_.empty()) {  // the volumes through the cut's ends to their nodes' ranks
    for (std::size_t k = 0; k < boundaries_.coupled.size(); ++k)
      if (steps_end(boundaries_.coupled[k].end))
        end_volume_[k] = state_.coupled(static_cast<Eigen::Index>(k)) - before(static_cast<Eigen::Index>(k));
    send_to_nodes(end_volume_);
  }
  std::fill(coupled_volume_.begin(), coupled_volume_.end(), 0.0);
  for (std::size_t k = 0; k < boundaries_.coupled.size(); ++k)
    if (coupled_slot_[k] >= 0)
      coupled_volume_[static_cast<std::size_t>(coupled_slot_[k])] +=
          steps_end(boundaries_.coupled[k].end) ? state_.coupled(static_cast<Eigen::Index>(k)) - before(static_cast<Eigen::Index>(k))
                                                : end_volume_[k];
}

void PulseSolver::sum_held_inflows() {
  // Each node's held inflow, summed over its ends in their order (another rank's sent first).
  if (!coupling_ranks_.empty()) send_to_nodes(held_end_flow_);
  std::fill(coupled_inflow_.begin(), coupled_inflow_.end(), 0.0);
  for (std::size_t k = 0; k < coupled_slot_.size(); ++k)  // (none on a share under the top)
    if (coupled_slot_[k] >= 0) coupled_inflow_[static_cast<std::size_t>(coupled_slot_[k])] += held_end_flow_[k];
}

void PulseSolver::keep_pass_start() {
  pass_start_.state = state_;
  pass_start_.previous_rate = previous_rate_;
  pass_start_.previous_flow = previous_flow_;
  pass_start_.ends = boundaries_.end_state;
  pass_start_.had_previous_rate = have_previous_rate_;
}

void PulseSolver::return_to_pass_start() {
  state_ = pass_start_.state;
  previous_rate_ = pass_start_.previous_rate;
  previous_flow_ = pass_start_.previous_flow;
  boundaries_.end_state = pass_start_.ends;
  have_previous_rate_ = pass_start_.had_previous_rate;
  time_ = step_start_;
}

void PulseSolver::take_substeps() {
  const double h = dt_ / substeps_;
  for (int k = 0; k < substeps_; ++k) {
    step_1d(h);
    time_ = step_start_ + (k + 1) * h;
  }
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

}  // namespace hemotree
