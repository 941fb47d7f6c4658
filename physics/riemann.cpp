#include "physics/riemann.hpp"

#include <array>
#include <cmath>
#include <vector>

#include <Eigen/Dense>

namespace hemotree {

void upwind_flux(const TubeLaw& law, double a_l, double q_l, double a_r, double q_r,
                 double& flux_area, double& flux_flow) {
  const double a = 0.5 * (a_l + a_r), q = 0.5 * (q_l + q_r);
  const double u = q / a, c = law.wave_speed(a);
  // H = [[0, 1], [c^2 - alpha u^2, 2 alpha u]]; |H| = (|l1| (H - l2 I) - |l2| (H - l1 I)) / (l1 - l2)
  const double h21 = c * c - law.alpha * u * u, h22 = 2 * law.alpha * u;
  const double l1 = law.lambda_forward(a, q), l2 = law.lambda_backward(a, q);
  const double m1 = std::abs(l1), m2 = std::abs(l2), d = l1 - l2;
  const double abs11 = (m1 * (-l2) - m2 * (-l1)) / d;
  const double abs12 = (m1 - m2) / d;
  const double abs21 = (m1 - m2) * h21 / d;
  const double abs22 = (m1 * (h22 - l2) - m2 * (h22 - l1)) / d;
  const double da = a_r - a_l, dq = q_r - q_l;
  flux_area = 0.5 * (q_l + q_r) - 0.5 * (abs11 * da + abs12 * dq);
  flux_flow = 0.5 * (law.flux_flow(a_l, q_l) + law.flux_flow(a_r, q_r)) -
              0.5 * (abs21 * da + abs22 * dq);
}

double incoming_speed(const TubeLaw& law, double a, double q, bool distal) {
  return distal ? law.lambda_backward(a, q) : law.lambda_forward(a, q);
}

EndState inflow_state(const TubeLaw& law, double a, double q, double q_in) {
  return {a + (q_in - q) / incoming_speed(law, a, q, false), q_in};
}

EndState resistance_state(const TubeLaw& law, double a, double q, double r, double p_beyond) {
  // Q* = q + mu (A* - a); solve g(A*) = p(A*) - r Q*(A*) - p_beyond = 0 by Newton.
  const double mu = incoming_speed(law, a, q, true);
  double x = a;
  for (int it = 0; it < 50; ++it) {
    const double qs = q + mu * (x - a);
    const double g = law.pressure(x) - r * qs - p_beyond;
    const double dg = law.pressure_slope(x) - r * mu;
    const double step = g / dg;
    x -= step;
    if (x <= 0) x = 0.5 * (x + step);  // stay in the physical range
    if (std::abs(step) <= 1e-14 * x) break;
  }
  return {x, q + mu * (x - a)};
}

EndState pressure_state(const TubeLaw& law, double a, double q, double p_node, bool distal, double r) {
  // Q* = q + mu (A* - a); solve p(A*) + rho (Q*/A*)^2 / 2 - r Q_in = p_node by Newton, as at a junction.
  const double mu = incoming_speed(law, a, q, distal), sign = distal ? 1.0 : -1.0;
  double x = a;
  for (int it = 0; it < 50; ++it) {
    const double qs = q + mu * (x - a), u = qs / x;
    const double g = law.total_pressure(x, qs) - r * sign * qs - p_node;
    const double dg = law.pressure_slope(x) + law.density * u * (mu - u) / x - r * sign * mu;
    const double step = g / dg;
    x -= step;
    if (x <= 0) x = 0.5 * (x + step);  // stay in the physical range
    if (std::abs(step) <= 1e-14 * x) break;
  }
  return {x, q + mu * (x - a)};
}

EndState reflection_state(const TubeLaw& law, double a, double q, double a0, double q0, double rt) {
  // Outgoing: Q* - q = mu_in (A* - a) (linearised at the trace).
  // Incoming, measured from rest: w_in = -rt w_out with w_k = l_k(U0) . (U* - U0),
  // l_out(U0) = (-lambda_in0, 1), l_in(U0) = (-lambda_out0, 1).
  const double mu = incoming_speed(law, a, q, true);
  const double lin0 = law.lambda_backward(a0, q0), lout0 = law.lambda_forward(a0, q0);
  // Unknowns (dA, dQ) = U* - U0:
  //   dQ - mu dA = q - q0 - mu (a - a0)
  //   (-lout0 dA + dQ) + rt (-lin0 dA + dQ) = 0
  Eigen::Matrix2d m;
  m << -mu, 1, -(lout0 + rt * lin0), 1 + rt;
  const Eigen::Vector2d rhs(q - q0 - mu * (a - a0), 0.0);
  const Eigen::Vector2d d = m.partialPivLu().solve(rhs);
  return {a0 + d(0), q0 + d(1)};
}

bool junction_state(std::span<const TubeLaw* const> laws, std::span<const double> a,
                    std::span<const double> q, std::span<const int> sign,
                    std::span<EndState> out) {
  const std::size_t n = laws.size();
  if (n < 2) return false;
  // Scratch on the stack for up to 16 ends (every branching and most measured confluences),
  // on the heap beyond: a node may join any number of vessels.
  constexpr std::size_t on_stack = 16;
  std::array<double, 5 * on_stack> stack;  // the first 5 n entries are used
  std::vector<double> heap;
  if (n > on_stack) heap.resize(5 * n);
  double* const scratch = n > on_stack ? heap.data() : stack.data();
  double *const mu = scratch, *const x = scratch + n, *const f = scratch + 2 * n, *const dpt = scratch + 3 * n,
                *const root_reference = scratch + 4 * n;
  for (std::size_t i = 0; i < n; ++i) {
    mu[i] = incoming_speed(*laws[i], a[i], q[i], sign[i] > 0);
    x[i] = out[i].area > 0 ? out[i].area : a[i];
    root_reference[i] = std::sqrt(laws[i]->reference_area);
  }
  for (int it = 0; it < 50; ++it) {
    // f_0 = sum sign Q* (mass); f_i = P_t,i - P_t,0 (total pressure), i >= 1. The Jacobian
    // is an arrowhead (row 0 full, then a diagonal and column 0): eliminated in O(n).
    double pt0 = 0, mass = 0;
    for (std::size_t i = 0; i < n; ++i) {
      // The tube law in sqrt(A): one square root per end and iteration.
      const TubeLaw& law = *laws[i];
      const double qs = q[i] + mu[i] * (x[i] - a[i]);
      const double u = qs / x[i], root = std::sqrt(x[i]);
      const double pt = law.pressure_of_root(root, root_reference[i]) + 0.5 * law.density * u * u;
      dpt[i] = law.pressure_slope_of_root(root) + law.density * u * (mu[i] - u) / x[i];
      mass += sign[i] * qs;
      if (i == 0) pt0 = pt;
      f[i] = pt;
    }
    f[0] = mass;
    for (std::size_t i = 1; i < n; ++i) f[i] -= pt0;
    // Row i >= 1: dpt_i dx_i - dpt_0 dx_0 = f_i; row 0: sum sign_i mu_i dx_i = f_0.
    double numerator = f[0], denominator = sign[0] * mu[0];
    for (std::size_t i = 1; i < n; ++i) {
      numerator -= sign[i] * mu[i] * f[i] / dpt[i];
      denominator += sign[i] * mu[i] * dpt[0] / dpt[i];
    }
    const double dx0 = numerator / denominator;
    double largest = std::abs(dx0) / x[0];
    x[0] -= dx0;
    for (std::size_t i = 1; i < n; ++i) {
      const double dx = (f[i] + dpt[0] * dx0) / dpt[i];
      x[i] -= dx;
      largest = std::max(largest, std::abs(dx) / x[i]);
    }
    for (std::size_t i = 0; i < n; ++i)
      if (!(x[i] > 0)) return false;
    // Newton converges quadratically here: after a relative step of 1e-9 the error left is
    // of order 1e-18, so the step that would confirm it is skipped.
    if (largest <= 1e-9) {
      for (std::size_t i = 0; i < n; ++i) out[i] = {x[i], q[i] + mu[i] * (x[i] - a[i])};
      return true;
    }
  }
  return false;
}

}  // namespace hemotree
