// The solution read out: at a fraction x along a vessel (a 1D vessel's modes at the point; a
// 0D vessel's from its lumped state), every vessel at once at one fraction (the cycle
// statistics), a vessel's mean flow, the network's blood volume, and the breakdown check.
#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "pulse/pulse_solver.hpp"
#include "pulse/solution_breakdown.hpp"

namespace hemotree {

void PulseSolver::locate(std::size_t vessel, double x, std::size_t& element, double& xi) const {
  const auto first = first_element(vessel), count = elements_per_vessel_;
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
  if (zero_d_[vessel]) return lumped_.flow_at(lumped_.vessel_index(vessel), std::clamp(x, 0.0, 1.0));
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
                             std::vector<double>* pressure) const {
  const std::size_t n = net_.vessel_count();
  area.resize(n);
  flow.resize(n);
  if (pressure) pressure->resize(n);
  if (n == 0) return;
  // The 0D vessels from their own state, then the 1D ones.
  lumped_.sample(std::clamp(x, 0.0, 1.0), area, flow, pressure ? std::span<double>(*pressure) : std::span<double>(), threads_);
  for_each_one_d_sample(x, pressure != nullptr, [&](std::size_t, std::size_t v, double a, double q, double p) {
    area[v] = a;
    flow[v] = q;
    if (pressure) (*pressure)[v] = p;
  });
}

void PulseSolver::sample_one_d(double x, std::span<double> area, std::span<double> flow, std::span<double> pressure) const {
  for_each_one_d_sample(x, !pressure.empty(), [&](std::size_t j, std::size_t, double a, double q, double p) {
    area[j] = a;
    flow[j] = q;
    if (!pressure.empty()) pressure[j] = p;
  });
}

template <class F>
void PulseSolver::for_each_one_d_sample(double x, bool with_pressure, F&& f) const {
  // The same element k and point xi in every vessel (locate's arithmetic). The 1D vessels are
  // listed in the order of their elements, with their first elements (first_element(v)'s,
  // without its search).
  const double s = std::clamp(x, 0.0, 1.0) * elements_per_vessel_;
  const auto k = std::min(static_cast<std::int32_t>(s), elements_per_vessel_ - 1);
  const double xi = 2 * (s - k) - 1;
  std::array<double, 32> phi;  // degrees are at most 30
  for (std::size_t j = 0; j <= static_cast<std::size_t>(max_degree()); ++j) phi[j] = legendre(static_cast<int>(j), xi);
  const auto one_d = static_cast<std::int64_t>(one_d_vessels_.size());
#pragma omp parallel for schedule(static) num_threads(threads_) if (threads_ > 1)
  for (std::int64_t j = 0; j < one_d; ++j) {
    const auto v = static_cast<std::size_t>(one_d_vessels_[static_cast<std::size_t>(j)]);
    const Eigen::Index el = one_d_first_element_[static_cast<std::size_t>(j)] + k;
    double a = 0, q = 0;
    for (int m = 0; m <= vessel_degree_[v]; ++m) {
      a += state_.area(el, m) * phi[static_cast<std::size_t>(m)];
      q += state_.flow(el, m) * phi[static_cast<std::size_t>(m)];
    }
    const double p = with_pressure ? (is_tapered(v) ? law_at(v, x).pressure(a) : element_law_[static_cast<std::size_t>(el)].pressure(a)) : 0.0;
    f(static_cast<std::size_t>(j), v, a, q, p);
  }
}

double PulseSolver::mean_flow(std::size_t vessel) const {
  if (zero_d_[vessel]) return lumped_.flow(lumped_.vessel_index(vessel));
  double sum = 0;
  for (auto el = first_element(vessel), end = end_element(vessel); el < end; ++el) sum += state_.flow(el, 0);
  return sum / elements_per_vessel_;
}

Eigen::VectorXd PulseSolver::boundary_volumes() const {
  Eigen::VectorXd volumes(static_cast<Eigen::Index>(lumped_boundary_volume_.size()));
  for (std::size_t b = 0; b < lumped_boundary_volume_.size(); ++b) volumes(static_cast<Eigen::Index>(b)) = boundary_volume(b);
  return volumes;
}

Eigen::Vector2d PulseSolver::exchanged_volumes() const {
  Eigen::Vector2d exchanged = Eigen::Vector2d::Zero();
  for (std::size_t b = 0; b < lumped_boundary_volume_.size(); ++b) {
    if (boundaries_.entering[b]) exchanged(0) += boundary_volume(b);
    else exchanged(1) -= boundary_volume(b);
  }
  return exchanged;
}

double PulseSolver::network_volume() const {
  // The 1D vessels' volumes and what the 0D scheme conserves (lumped_vessels.hpp).
  double volume = lumped_.stored_volume();
  for (std::size_t v = 0; v < net_.vessel_count(); ++v)
    for (auto el = first_element(v), end = end_element(v); el < end; ++el) volume += 2 * half_length_(el) * state_.area(el, 0);
  return volume;
}

std::vector<double> PulseSolver::one_d_volumes(std::size_t vessel) const {
  std::vector<double> terms;
  for (auto el = first_element(vessel), end = end_element(vessel); el < end; ++el) terms.push_back(2 * half_length_(el) * state_.area(el, 0));
  return terms;
}

std::vector<std::int32_t> PulseSolver::held_boundaries() const {
  std::vector<std::int32_t> held = lumped_.boundaries();
  for (const auto* given : {&boundaries_.flows, &boundaries_.pressures})
    for (const auto& g : *given)
      if (one_d_here_ && steps_end(g.end)) held.push_back(g.index);
  for (const auto& o : boundaries_.outlets)
    if (one_d_here_ && steps_end(o.end)) held.push_back(o.boundary);
  std::sort(held.begin(), held.end());
  return held;
}

void PulseSolver::check_solution() const {
  lumped_.check(time_, net_.id);
  for (const ElementRun& r : runs_)
    for (Eigen::Index el = r.first; el < r.first + r.count; ++el)
      if (!(state_.area(el, 0) > 0) || !state_.area.row(el).allFinite() || !state_.flow.row(el).allFinite())
        throw SolutionBreakdown(net_.id[static_cast<std::size_t>(element_vessel_[el])], time_);
}

}  // namespace hemotree
