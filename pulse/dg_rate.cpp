// The DG rate of the 1D vessels (docs/solver.md §1-4): the time derivative of every element's
// modal coefficients W = (A, Q), given the state and the time (PulseSolver::evaluate). As in
// Nektar++'s PulseWaveSolver, flux and source apart, and each kind of face its own step:
//
//   dW_j/dt = (1/J) M_jj^-1 [ sum_q w_q P_j'(xi_q) F(U_q) - (P_j(1) F*_R - P_j(-1) F*_L) ]
//             + M_jj^-1 sum_q w_q P_j(xi_q) S(U_q)
//   F(U) = (Q, alpha Q^2 / A + beta A^(3/2) / (3 rho)),   S(U) = (0, -k mu(A) Q / (rho A))
//
//   volume_terms           U at the quadrature points, the volume integral of F, S there, traces
//   interior_face_fluxes   F* between consecutive elements of a vessel (upwind, Roe)
//   prescribed_end_fluxes  F(U*) at given flows and pressures
//   coupled_end_fluxes     F(U*) at ends on nodes of 0D vessels (a Robin condition)
//   outlet_end_fluxes      F(U*) at R, RCR (and dp_c/dt) and reflection outlets
//   boundary_exchange      the volumes through the boundaries, summed in a fixed order
//   junction_fluxes        the Riemann problem of each junction (mass, total pressure)
//   lift_to_rate           the surface term, 1/J and the source's projection
//
// Every step acts on all elements at once through flat arrays (rows of elements; one trace and
// one end flux per element and side); U* at a vessel end is the node's (physics/riemann.hpp).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <omp.h>

#include "core/parallel_errors.hpp"
#include "pulse/pulse_solver.hpp"
#include "boundaries/coupled_node.hpp"
#include "boundaries/flow_inlet.hpp"
#include "boundaries/pressure_end.hpp"
#include "boundaries/rcr_outlet.hpp"
#include "boundaries/reflection_outlet.hpp"
#include "boundaries/resistance_outlet.hpp"
#include "physics/riemann.hpp"
#include "pulse/solution_breakdown.hpp"

namespace hemotree {

void PulseSolver::evaluate(double t, const PulseState& s, PulseState& rate) {
  const Eigen::Index elements = s.area.rows();
  // Every used mode of every rate is written below; the padding columns of lower degrees
  // must stay zero, so the storage is cleared only when it is (re)allocated.
  if (rate.area.rows() != elements || rate.area.cols() != s.area.cols() ||
      rate.capacitor.size() != s.capacitor.size() || rate.coupled.size() != s.coupled.size() ||
      rate.boundary.size() != s.boundary.size() || rate.faces.size() != s.faces.size())
    rate.set_zero_like(s);
  friction_rate_.resize(elements);
  for (Eigen::VectorXd* v : {&area_left_, &area_right_, &flow_left_, &flow_right_, &flux_a_left_,
                             &flux_a_right_, &flux_q_left_, &flux_q_right_})
    v->resize(elements);

  // Spread over ranks a failure is kept for the step's end (settle_failures), where the first
  // of every rank's is said on all of them: one reduction a step, not one an evaluation. A rank
  // that has failed in this step computes nothing more, but keeps its neighbours' exchanges.
  const auto evaluation = static_cast<std::int64_t>(evaluation_times_.size());
  if (one_d_cut_) {
    evaluation_times_.push_back(t);
    if (first_failure_ != no_failure) {
      exchange_traces();
      return;
    }
  }
  const Eigen::Index bad_element = volume_terms(s, rate);
  if (bad_element >= 0 && !one_d_cut_) throw SolutionBreakdown(failed_vessel(bad_element), t);
  if (one_d_cut_) exchange_traces();
  std::int64_t bad_junction = -1;
  if (bad_element < 0) {
    interior_face_fluxes();
    prescribed_end_fluxes(t);
    coupled_end_fluxes(t, rate);
    outlet_end_fluxes(s, rate);
    boundary_exchange(rate);
    bad_junction = junction_fluxes();
  }
  if (bad_element >= 0 || bad_junction >= 0) {
    // The one process's order: an element's failure (the least) before any junction's.
    const std::int64_t key = bad_element >= 0 ? bad_element : elements + bad_junction;
    if (!one_d_cut_) throw SolutionBreakdown(failed_vessel(key), t);
    first_failure_ = evaluation * failure_keys() + key;
    return;
  }
  lift_to_rate(rate);
}

std::int64_t PulseSolver::failed_vessel(std::int64_t key) const {
  const auto elements = static_cast<std::int64_t>(element_vessel_.size());
  if (key < elements) return net_.id[static_cast<std::size_t>(element_vessel_[static_cast<std::size_t>(key)])];
  const auto first = boundaries_.junction_offset[static_cast<std::size_t>(key - elements)];
  return net_.id[static_cast<std::size_t>(boundaries_.junction_ends[static_cast<std::size_t>(first)].vessel)];
}

void PulseSolver::settle_failures() {
  const std::int64_t first = least_key_(first_failure_);
  std::vector<double> times;
  std::swap(times, evaluation_times_);
  first_failure_ = no_failure;
  if (first == no_failure) return;
  throw SolutionBreakdown(failed_vessel(first % failure_keys()), times[static_cast<std::size_t>(first / failure_keys())]);
}

// The element-local part of the right-hand side for elements [first, first + count): point
// values, volume fluxes, friction, traces. Rows are independent, so blocks run in parallel
// and give the same bits whatever the number of threads.
Eigen::Index PulseSolver::element_terms(const PulseState& s, PulseState& rate, const ModalBasis& basis,
                                        Eigen::Index first, Eigen::Index count) {
  const double rho = blood_.density, alpha = blood_.momentum_alpha();
  const Eigen::Index modes = basis.degree + 1, points = basis.points;
  auto area_q = area_q_.block(first, 0, count, points);
  auto flow_q = flow_q_.block(first, 0, count, points);
  auto flux_q = flux_q_.block(first, 0, count, points);
  auto source_q = source_q_.block(first, 0, count, points);
  const auto area = s.area.block(first, 0, count, modes), flow = s.flow.block(first, 0, count, modes);
  area_q.noalias() = area.lazyProduct(basis.at_points.transpose());
  flow_q.noalias() = flow.lazyProduct(basis.at_points.transpose());
  if (!(area_q.array() > 0).all() || !area_q.allFinite()) {
    for (Eigen::Index el = 0; el < count; ++el)
      if (!(area_q.row(el).array() > 0).all() || !area_q.row(el).allFinite()) return first + el;
  }

  // Volume term: (F(U), dphi/dx) for both equations.
  flux_q.array() = alpha * flow_q.array().square() / area_q.array() +
                   TubeLaw::pressure_flux(
                       (element_beta_.segment(first, count).array() / (3 * rho)).replicate(1, area_q.cols()), area_q.array());
  // Tapered elements: beta varies between the points.
  const auto tapered_begin = std::lower_bound(tapered_elements_.begin(), tapered_elements_.end(), first);
  const auto tapered_end = std::lower_bound(tapered_begin, tapered_elements_.end(), first + count);
  for (auto it = tapered_begin; it != tapered_end; ++it) {
    const Eigen::Index el = *it - first, row = it - tapered_elements_.begin();
    for (Eigen::Index q = 0; q < points; ++q) {
      const double a = area_q(el, q), u = flow_q(el, q);
      flux_q(el, q) = alpha * u * u / a + TubeLaw::pressure_flux(taper_beta_(row, q) / (3 * rho), a);
    }
  }
  rate.area.block(first, 0, count, modes).noalias() = flow_q.lazyProduct(basis.weak_derivative.transpose());
  rate.flow.block(first, 0, count, modes).noalias() = flux_q.lazyProduct(basis.weak_derivative.transpose());

  // Friction -r Q with r = k mu / (rho A) at each point, mu at the local diameter (Pries) or
  // constant. Column by column: the storage order.
  for (Eigen::Index q = 0; q < points; ++q)
    for (Eigen::Index el = 0; el < count; ++el) {
      const double a = area_q(el, q);
      source_q(el, q) = friction_k_ * viscosity_(a) / (rho * a);
    }
  if (element_viscosity_factor_.size() > 0)
    source_q = element_viscosity_factor_.segment(first, count).asDiagonal() * source_q;
  // Each element's friction rate, r averaged over the element: the exponential scheme
  // integrates -r Q exactly and leaves only the variation of r within the element explicit.
  friction_rate_.segment(first, count).noalias() = source_q.lazyProduct(basis.rule.weights) / 2;
  source_q.array() *= -flow_q.array();
  // Tapered elements: the part of the pressure force that the flux does not hold,
  // A (g1 sqrt(A) + g0) (physics/vessel_taper.hpp, docs/solver.md §1a).
  for (auto it = tapered_begin; it != tapered_end; ++it) {
    const Eigen::Index el = *it - first, row = it - tapered_elements_.begin();
    for (Eigen::Index q = 0; q < points; ++q) {
      const double a = area_q(el, q);
      source_q(el, q) += a * (taper_g1_(row, q) * std::sqrt(a) + taper_g0_(row, q));
    }
  }

  // Traces at both ends of every element.
  area_left_.segment(first, count).noalias() = area.lazyProduct(basis.left.transpose());
  area_right_.segment(first, count).noalias() = area.lazyProduct(basis.right.transpose());
  flow_left_.segment(first, count).noalias() = flow.lazyProduct(basis.left.transpose());
  flow_right_.segment(first, count).noalias() = flow.lazyProduct(basis.right.transpose());
  return -1;
}

Eigen::Index PulseSolver::volume_terms(const PulseState& s, PulseState& rate) {
  // Element terms: each degree's block split into one part per thread, in one parallel
  // region (a region per block cost more than the 1D vessels' work on a million-vessel tree).
  Eigen::Index bad = -1;
  ParallelErrors errors;
#pragma omp parallel num_threads(threads_) if (threads_ > 1)
  {
    const int threads = omp_get_num_threads(), me = omp_get_thread_num();
    for (const ElementRun& b : runs_) {
      const ModalBasis& basis = bases_[static_cast<std::size_t>(b.degree)];
      const Eigen::Index first = b.first + b.count * me / threads, last = b.first + b.count * (me + 1) / threads;
      errors.guard(first, [&] {
        const Eigen::Index found = element_terms(s, rate, basis, first, last - first);
        if (found >= 0) {
#pragma omp critical
          bad = bad < 0 ? found : std::min(bad, found);
        }
      });
    }
  }
  errors.rethrow();
  return bad;
}

void PulseSolver::interior_face_fluxes() {
  // Interfaces inside vessels: between consecutive elements of one vessel (a loop over the
  // elements, not the vessels: a full tree's millions of 0D vessels have none). A vessel's
  // elements lie in one run.
  for (const ElementRun& run : runs_) {
    if (elements_per_vessel_ == 1) break;
    const Eigen::Index last = run.first + run.count - 1;
#pragma omp parallel for schedule(static) num_threads(threads_) if (threads_ > 1)
    for (Eigen::Index el = run.first; el < last; ++el) {
      const std::int32_t v = element_vessel_[static_cast<std::size_t>(el)];
      if (element_vessel_[static_cast<std::size_t>(el) + 1] != v) continue;
      double fa, fq;
      // In a tapered vessel, the law at the interface itself.
      const TubeLaw& law = taper_row_.empty() || taper_row_[static_cast<std::size_t>(el)] < 0
                                 ? element_law_[static_cast<std::size_t>(el)]
                                 : taper_right_law_[static_cast<std::size_t>(taper_row_[static_cast<std::size_t>(el)])];
      upwind_flux(law, area_right_(el), flow_right_(el), area_left_(el + 1), flow_left_(el + 1), fa, fq);
      flux_a_right_(el) = flux_a_left_(el + 1) = fa;
      flux_q_right_(el) = flux_q_left_(el + 1) = fq;
    }
  }
}

// Vessel ends: the node supplies U*, the flux is F(U*).
void PulseSolver::set_end_flux(const VesselEnd& end, const EndState& u) {
  const TubeLaw& law = end_law(static_cast<std::size_t>(end.vessel), end.distal);
  const double fa = u.flow, fq = law.flux_flow(u.area, u.flow);
  if (end.distal) {
    flux_a_right_(end.element) = fa;
    flux_q_right_(end.element) = fq;
  } else {
    flux_a_left_(end.element) = fa;
    flux_q_left_(end.element) = fq;
  }
  boundaries_.state_at(end) = u;
}

void PulseSolver::trace(const VesselEnd& end, double& a, double& q) const {
  a = end.distal ? area_right_(end.element) : area_left_(end.element);
  q = end.distal ? flow_right_(end.element) : flow_left_(end.element);
}

void PulseSolver::prescribed_end_fluxes(double t) {
  // Prescribed flows into the network (boundaries/flow_inlet.hpp).
  for (const auto& f : boundaries_.flows) {
    if (!steps_end(f.end)) continue;
    double a, q;
    trace(f.end, a, q);
    const double q_in = boundaries_.list.waveform(static_cast<std::size_t>(f.index))(t);
    const TubeLaw& law = end_law(static_cast<std::size_t>(f.end.vessel), f.end.distal);
    set_end_flux(f.end, FlowInlet{q_in}.end_state(law, a, q, f.end.distal));
  }
  // Prescribed pressures (boundaries/pressure_end.hpp).
  for (const auto& g : boundaries_.pressures) {
    if (!steps_end(g.end)) continue;
    double a, q;
    trace(g.end, a, q);
    const double p = boundaries_.list.waveform(static_cast<std::size_t>(g.index))(t);
    set_end_flux(g.end, PressureEnd{p}.end_state(end_law(static_cast<std::size_t>(g.end.vessel), g.end.distal), a, q,
                                                 g.end.distal));
  }
}

void PulseSolver::coupled_end_fluxes(double t, PulseState& rate) {
  // Ends at nodes of 0D vessels: the node's pressure, moving through the 0D step
  // (boundaries/coupled_node.hpp).
  for (std::size_t k = 0; k < boundaries_.coupled.size(); ++k) {
    const auto& c = boundaries_.coupled[k];
    if (!steps_end(c.end)) continue;  // another rank's
    double a, q;
    trace(c.end, a, q);
    // The node's response r = 3/2 Z (docs/solver.md §10), its pressure at this point of the step
    // (spread over ranks, a node of another rank's as it sent it: the same arithmetic).
    const double s = dt_ > 0 ? std::clamp((t - step_start_) / dt_, 0.0, 1.0) : 0.0;
    double p, z, dynamic;
    if (coupled_slot_[k] >= 0) {
      const auto slot = static_cast<std::size_t>(coupled_slot_[k]);
      p = lumped_.pressure_during_step(slot, s);
      z = lumped_.impedance(slot);
      dynamic = lumped_.dynamic_pressure(slot);
    } else {
      const auto& [p0, predicted, impedance, dynamic_there] = remote_node_[k];
      p = p0 + s * (predicted - p0);
      z = impedance;
      dynamic = dynamic_there;
    }
    const double r = 1.5 * z;
    const CoupledNode coupled{p, dynamic, r, held_end_flow_[k]};
    const EndState u = coupled.end_state(end_law(static_cast<std::size_t>(c.end.vessel), c.end.distal), a, q, c.end.distal);
    set_end_flux(c.end, u);
    rate.coupled(static_cast<Eigen::Index>(k)) = CoupledNode::flow_into_node(u, c.end.distal);
  }
}

void PulseSolver::outlet_end_fluxes(const PulseState& s, PulseState& rate) {
  const auto outlets = static_cast<std::int64_t>(boundaries_.outlets.size());
#pragma omp parallel for schedule(static) num_threads(threads_) if (threads_ > 1)
  for (std::int64_t k = 0; k < outlets; ++k) {
    const auto& o = boundaries_.outlets[static_cast<std::size_t>(k)];
    if (!steps_end(o.end)) continue;
    double a, q;
    trace(o.end, a, q);
    const TubeLaw& law = end_law(static_cast<std::size_t>(o.end.vessel), o.end.distal);
    // The distal end's conditions; at a proximal end on the mirrored state, the flow negated
    // back after (sign: along the vessel, out of the network).
    const double sign = o.end.distal ? 1.0 : -1.0;
    q *= sign;
    EndState u;
    // The outlet models (boundaries/*_outlet.hpp).
    switch (o.outlet.type) {
      case BoundaryType::resistance:
        u = ResistanceOutlet{o.outlet.r, o.outlet.p_out}.end_state(law, a, q);
        break;
      case BoundaryType::rcr: {
        const RcrOutlet rcr{o.outlet.r1, o.outlet.c, o.outlet.r2, o.outlet.p_out};
        if (o.capacitor < 0) {  // no compliance
          u = rcr.series_end_state(law, a, q);
        } else {
          const double pc = s.capacitor(o.capacitor);
          u = rcr.end_state(law, a, q, pc);
          rate.capacitor(o.capacitor) = rcr.capacitor_rate(u.flow, pc);
        }
        break;
      }
      case BoundaryType::reflection:
        u = ReflectionOutlet{o.outlet.reflection, o.rest_area, sign * o.rest_flow}.end_state(law, a, q);
        break;
      case BoundaryType::flow:
      case BoundaryType::pressure:
        break;  // prescribed ends, not outlets
    }
    u.flow *= sign;
    set_end_flux(o.end, u);
  }
}

void PulseSolver::boundary_exchange(PulseState& rate) const {
  // The volume flux in through each boundary at a 1D end; an end's flow is positive along
  // the vessel.
  auto leaving = [&](const VesselEnd& end) {
    const double q = boundaries_.state_at(end).flow;
    return end.distal ? q : -q;
  };
  for (const auto* given : {&boundaries_.flows, &boundaries_.pressures})
    for (const auto& g : *given)
      if (steps_end(g.end)) rate.boundary(g.slot) = -leaving(g.end);
  for (const auto& o : boundaries_.outlets)
    if (steps_end(o.end)) rate.boundary(o.slot) = -leaving(o.end);
}

std::int64_t PulseSolver::junction_fluxes() {
  // Junctions are independent: each writes only its own ends' fluxes. Spread over ranks, those
  // with an end of this rank's (their other ends' traces received).
  const auto junctions = one_d_cut_ ? static_cast<std::int64_t>(one_d_cut_->junctions.size())
                                    : static_cast<std::int64_t>(boundaries_.junction_offset.size()) - 1;
  std::int64_t failed_junction = -1;
  // A junction of many vessels allocates its scratch (an exception must not leave the region).
  parallel_blocks(junctions, threads_, [&](std::int64_t first_junction, std::int64_t last_junction) {
    for (std::int64_t i = first_junction; i < last_junction; ++i) {
      const std::int64_t jj = one_d_cut_ ? one_d_cut_->junctions[static_cast<std::size_t>(i)] : i;
      const auto j = static_cast<std::size_t>(jj);
      // Left uninitialised: only the first `count` entries are used (zeroing all 16 was 5 % of a step).
      // A node of more than 16 vessels (measured networks) takes its scratch from the heap.
      constexpr std::size_t on_stack = 16;
      std::array<const TubeLaw*, on_stack> laws_stack;
      std::array<double, on_stack> ja_stack, jq_stack;
      std::array<int, on_stack> sign_stack;
      std::array<EndState, on_stack> out_stack;
      const auto first = boundaries_.junction_offset[j], last = boundaries_.junction_offset[j + 1];
      const auto count = static_cast<std::size_t>(last - first);
      std::vector<const TubeLaw*> laws_heap;
      std::vector<double> ja_heap, jq_heap;
      std::vector<int> sign_heap;
      std::vector<EndState> out_heap;
      const TubeLaw** laws = laws_stack.data();
      double *ja = ja_stack.data(), *jq = jq_stack.data();
      int* sign = sign_stack.data();
      EndState* out = out_stack.data();
      if (count > on_stack) {
        laws_heap.resize(count);
        ja_heap.resize(count);
        jq_heap.resize(count);
        sign_heap.resize(count);
        out_heap.resize(count);
        laws = laws_heap.data();
        ja = ja_heap.data();
        jq = jq_heap.data();
        sign = sign_heap.data();
        out = out_heap.data();
      }
      for (std::size_t i = 0; i < count; ++i) {
        const VesselEnd& end = boundaries_.junction_ends[static_cast<std::size_t>(first) + i];
        laws[i] = &end_law(static_cast<std::size_t>(end.vessel), end.distal);
        trace(end, ja[i], jq[i]);
        sign[i] = end.distal ? 1 : -1;
        out[i] = boundaries_.state_at(end);
      }
      if (!junction_state({laws, count}, {ja, count}, {jq, count}, {sign, count}, {out, count})) {
#pragma omp critical
        failed_junction = failed_junction < 0 ? jj : std::min(failed_junction, jj);
        continue;
      }
      for (std::size_t i = 0; i < count; ++i)
        set_end_flux(boundaries_.junction_ends[static_cast<std::size_t>(first) + i], out[i]);
    }
  });
  return failed_junction;
}

void PulseSolver::lift_to_rate(PulseState& rate) const {
  // Surface term and scaling: dC/dt = (volume - M^-1 (phi(1) F*_R - phi(-1) F*_L)) / J + source.
  // Each degree's block split into one part per thread, in one parallel region.
#pragma omp parallel num_threads(threads_) if (threads_ > 1)
  {
    const int threads = omp_get_num_threads(), me = omp_get_thread_num();
    for (const ElementRun& b : runs_) {
      const ModalBasis& basis = bases_[static_cast<std::size_t>(b.degree)];
      const auto right = basis.inverse_mass.cwiseProduct(basis.right);  // lifts of the end fluxes
      const auto left = basis.inverse_mass.cwiseProduct(basis.left);
      const Eigen::Index modes = b.degree + 1;
      const Eigen::Index first = b.first + b.count * me / threads,
                         count = b.first + b.count * (me + 1) / threads - first;
      auto ra = rate.area.block(first, 0, count, modes);
      auto rq = rate.flow.block(first, 0, count, modes);
      ra.noalias() -= flux_a_right_.segment(first, count) * right;
      ra.noalias() += flux_a_left_.segment(first, count) * left;
      rq.noalias() -= flux_q_right_.segment(first, count) * right;
      rq.noalias() += flux_q_left_.segment(first, count) * left;
      const auto inverse_jacobian = half_length_.segment(first, count).cwiseInverse().asDiagonal();
      ra = inverse_jacobian * ra;
      rq = inverse_jacobian * rq;
      rq.noalias() += source_q_.block(first, 0, count, basis.points).lazyProduct(basis.projection.transpose());
    }
  }
  // Tapered elements: less the rest state's residual (compute_rest_correction).
  for (std::size_t row = 0; row < tapered_elements_.size(); ++row)
    rate.flow.row(tapered_elements_[row]) -= taper_rest_.row(static_cast<Eigen::Index>(row));
  if (rate.faces.size() > 0) rate.faces = flux_a_left_;
}

}  // namespace hemotree
