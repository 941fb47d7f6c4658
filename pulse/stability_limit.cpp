#include "pulse/stability_limit.hpp"

#include <algorithm>
#include <map>
#include <mutex>
#include <utility>
#include <numbers>

#include <Eigen/Eigenvalues>

#include "pulse/legendre_basis.hpp"

namespace hemotree {

std::vector<std::complex<double>> dg_advection_spectrum(int degree, int waves) {
  // Per theta, 2 M^-1 (K - e_R 1^T + e^(-i theta) e_L 1^T) on the reference element [-1, 1]
  // (the 2 maps it to unit length): K_ij = int P_j P_i', e_R = P_i(1) = 1,
  // e_L = P_i(-1) = (-1)^i, M = diag(2 / (2i + 1)); upwind flux for a positive speed.
  using C = std::complex<double>;
  const int m = degree + 1;
  const GaussLegendre rule = gauss_legendre(degree + 2);
  Eigen::MatrixXd k(m, m);
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) {
      double sum = 0;
      for (Eigen::Index q = 0; q < rule.nodes.size(); ++q)
        sum += rule.weights(q) * legendre(j, rule.nodes(q)) * legendre_derivative(i, rule.nodes(q));
      k(i, j) = sum;
    }
  std::vector<C> spectrum;
  spectrum.reserve(static_cast<std::size_t>(waves * m));
  Eigen::MatrixXcd a(m, m);
  for (int t = 0; t < waves; ++t) {
    const C upstream = std::exp(C(0, -2 * std::numbers::pi * t / waves));
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < m; ++j)
        a(i, j) = static_cast<double>(2 * i + 1) * (k(i, j) - 1.0 + (i % 2 == 0 ? 1.0 : -1.0) * upstream);
    const Eigen::ComplexEigenSolver<Eigen::MatrixXcd> eigen(a, false);
    for (int i = 0; i < m; ++i) spectrum.push_back(eigen.eigenvalues()(i));
  }
  return spectrum;
}

double amplification(TimeScheme scheme, std::complex<double> z) {
  if (scheme == TimeScheme::runge_kutta4) return std::abs(1.0 + z * (1.0 + z * (0.5 + z * (1.0 / 6 + z / 24.0))));
  // Roots of AB2's characteristic polynomial s^2 - (1 + 3z/2) s + z/2.
  const std::complex<double> b = -(1.0 + 1.5 * z), c = 0.5 * z, d = std::sqrt(b * b - 4.0 * c);
  return std::max(std::abs((-b + d) / 2.0), std::abs((-b - d) / 2.0));
}

double growth_tolerance(TimeScheme scheme) { return scheme == TimeScheme::runge_kutta4 ? 1e-12 : 3e-5; }

namespace {
double compute_courant_limit(int degree, TimeScheme scheme) {
  const auto spectrum = dg_advection_spectrum(degree);
  const double tolerance = growth_tolerance(scheme);
  auto stable = [&](double nu) {
    return std::all_of(spectrum.begin(), spectrum.end(),
                       [&](auto s) { return amplification(scheme, nu * s) <= 1 + tolerance; });
  };
  // Walk up from a step every scheme takes (nu |s| = 0.05) to the first unstable one, then
  // bisect: the first loss of stability is the limit (larger, stable islands don't count).
  double radius = 0;
  for (const auto s : spectrum) radius = std::max(radius, std::abs(s));
  double lo = 0.05 / radius, hi = lo;
  while (stable(hi)) {
    lo = hi;
    hi *= 1.05;
  }
  while (hi - lo > 1e-3 * lo) {
    const double mid = 0.5 * (lo + hi);
    (stable(mid) ? lo : hi) = mid;
  }
  return lo;
}
}  // namespace

double courant_limit(int degree, TimeScheme scheme) {
  // Computed once per degree and scheme (about 10 ms each: 128 eigenproblems and a search).
  static std::mutex guard;
  static std::map<std::pair<int, TimeScheme>, double> known;
  const std::lock_guard<std::mutex> lock(guard);
  const auto key = std::make_pair(degree, scheme);
  auto it = known.find(key);
  if (it == known.end()) it = known.emplace(key, compute_courant_limit(degree, scheme)).first;
  return it->second;
}

}  // namespace hemotree
