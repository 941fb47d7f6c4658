#include "harmonic/mean_shift.hpp"

#include <cmath>

namespace hemotree {

PulseMoments pulse_moments(const VesselLine& line, std::span<const double> omega, std::span<const std::complex<double>> p_from,
                           std::span<const std::complex<double>> p_to, double x) {
  PulseMoments m;
  for (std::size_t k = 0; k < omega.size(); ++k) {
    const VesselLine::Matrix a = line.matrix(omega[k]);
    const std::complex<double> p = line.pressure(omega[k], p_from[k], p_to[k], x), q = line.flow(omega[k], p_from[k], p_to[k], x);
    const std::complex<double> dp = a.tau * p + a.m12 * q, dq = a.m21 * p;  // d/dx (P, Q) = M (P, Q)
    m.pp += 0.5 * std::norm(p);
    m.qq += 0.5 * std::norm(q);
    m.pq += 0.5 * (p * std::conj(q)).real();
    m.dpp += (dp * std::conj(p)).real();
    m.dqq += (dq * std::conj(q)).real();
    m.dpq += 0.5 * (dp * std::conj(q) + p * std::conj(dq)).real();
  }
  return m;
}

double mean_forcing(const VesselLine& line, const LumenSlopes& s, double density, const PulseMoments& m) {
  const double area = density / line.inertance, c1 = line.compliance, c2 = s.area_curvature;
  const double r = line.resistance, q0 = line.mean_velocity * area;
  const double gradient = -r * q0;  // p0' of the steady flow
  // The friction F = (A / rho) R'(A) Q and its derivatives at (A, Q0).
  const double f_a = q0 * (r + area * s.resistance_slope) / density;
  const double f_aa = q0 * (2 * s.resistance_slope + area * s.resistance_curvature) / density;
  const double f_aq = (r + area * s.resistance_slope) / density;
  const double a2 = area * area, a3 = a2 * area;
  // T' = d/dx of the mean momentum flux's pulse part
  const double flux_slope = line.alpha * (m.dqq / area - 2 * q0 * c1 * m.dpq / a2 + q0 * q0 * c1 * c1 * m.dpp / a3 -
                                  0.5 * q0 * q0 * c2 * m.dpp / a2);
  const double n = (0.5 * c2 * m.pp * gradient + 0.5 * c1 * m.dpp) / density + 0.5 * f_a * c2 * m.pp +
                   0.5 * f_aa * c1 * c1 * m.pp + f_aq * c1 * m.pq + flux_slope;
  return density / area * n;
}

double mean_kinetic_pressure(const VesselLine& line, const LumenSlopes& s, double density, const PulseMoments& m) {
  const double area = density / line.inertance, c1 = line.compliance, u0 = line.mean_velocity;
  const double a2 = area * area;
  // u = U0 + (q1 - U0 a1) / A + second-order mean terms (a = C' p1 + C'' p1^2 / 2).
  const double oscillation = (m.qq - 2 * u0 * c1 * m.pq + u0 * u0 * c1 * c1 * m.pp) / a2;
  const double mean_u = -c1 * m.pq / a2 + u0 * c1 * c1 * m.pp / a2 - 0.5 * u0 * s.area_curvature * m.pp / area;
  return 0.5 * density * (u0 * u0 + oscillation + 2 * u0 * mean_u);
}

namespace {
double line_d(const VesselLine& line) {
  return 1 - line.alpha * line.mean_velocity * line.mean_velocity * line.inertance * line.compliance;
}
}  // namespace

std::vector<double> forcing_drops(const VesselLine& line, const LumenSlopes& slopes, double density,
                                  std::span<const double> omega, std::span<const std::complex<double>> p_from,
                                  std::span<const std::complex<double>> p_to, int intervals) {
  const double d = line_d(line), h = line.length / intervals, growth = std::exp(line.kappa / d * h);
  std::vector<double> drops(static_cast<std::size_t>(intervals) + 1, 0.0);
  double g_before = mean_forcing(line, slopes, density, pulse_moments(line, omega, p_from, p_to, 0.0)) / d;
  for (int i = 1; i <= intervals; ++i) {
    const double g = mean_forcing(line, slopes, density, pulse_moments(line, omega, p_from, p_to, i * h)) / d;
    drops[static_cast<std::size_t>(i)] = growth * drops[static_cast<std::size_t>(i - 1)] + 0.5 * h * (growth * g_before + g);
    g_before = g;
  }
  return drops;
}

std::vector<double> mean_shift_profile(const VesselLine& line, double dp_from, double dq, std::span<const double> drops) {
  const double d = line_d(line), tau = line.kappa / d;
  const std::size_t intervals = drops.size() - 1;
  std::vector<double> shift(drops.size());
  for (std::size_t i = 0; i < drops.size(); ++i) {
    const double x = line.length * static_cast<double>(i) / static_cast<double>(intervals), e = std::exp(tau * x);
    const double span = tau * x == 0 ? x : std::expm1(tau * x) / tau;
    shift[i] = e * dp_from - line.resistance / d * dq * span - drops[i];
  }
  return shift;
}

}  // namespace hemotree
