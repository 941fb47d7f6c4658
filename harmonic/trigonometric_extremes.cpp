#include "harmonic/trigonometric_extremes.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace hemotree {

namespace {

// f and its first two derivatives at theta.
struct Derivatives {
  double f, df, d2f;
};

Derivatives evaluate(std::span<const std::complex<double>> c, double theta) {
  const std::complex<double> step = std::polar(1.0, theta);
  std::complex<double> e = step;
  Derivatives d{0, 0, 0};
  for (std::size_t j = 0; j < c.size(); ++j, e *= step) {
    const double k = static_cast<double>(j + 1);
    const std::complex<double> term = c[j] * e;
    d.f += term.real();
    d.df -= k * term.imag();
    d.d2f -= k * k * term.real();
  }
  return d;
}

// The extreme (sign +1: greatest, -1: least) of f near theta0, kept within h of it, by Newton's
// method from theta: it converges quadratically, and once a step would be below 1e-7, f where
// it starts is within |f''| 1e-14 / 2 of the extreme.
double refine(std::span<const std::complex<double>> c, double theta0, double theta, double f0, double h, double sign) {
  double best = f0;
  for (int iteration = 0; iteration < 8; ++iteration) {
    const Derivatives d = evaluate(c, theta);
    if (sign * d.f > sign * best) best = d.f;
    if (sign * d.d2f >= 0) break;  // not concave towards the extreme: Newton would leave it
    const double step = -d.df / d.d2f;
    if (std::abs(step) <= 1e-7) break;
    theta = std::clamp(theta + step, theta0 - h, theta0 + h);
  }
  return best;
}

// f at the M samples: f_m = sum_k Re c_k cos(k theta_m) - Im c_k sin(k theta_m), a row of the
// tables per harmonic. Compiled for the wider vector units too (chosen when the program
// starts): the sum over k is taken in the same order in every lane and, with no contraction
// into fused multiply-adds (CMakeLists.txt), to the same bits on every machine.
__attribute__((target_clones("avx512f", "avx2", "default"))) double sample(
    std::span<const std::complex<double>> c, const double* cosine, const double* sine, double* f, std::size_t m_count) {
  std::fill(f, f + m_count, 0.0);
  double bound = 0;  // S = sum k^2 |c_k|
  for (std::size_t j = 0; j < c.size(); ++j) {
    const double re = c[j].real(), im = c[j].imag();
    const double* cos_k = cosine + j * m_count;
    const double* sin_k = sine + j * m_count;
    for (std::size_t m = 0; m < m_count; ++m) f[m] += re * cos_k[m] - im * sin_k[m];
    bound += static_cast<double>((j + 1) * (j + 1)) * (std::abs(re) + std::abs(im));  // >= k^2 |c_k|
  }
  return bound;
}

}  // namespace

TrigonometricExtremes::TrigonometricExtremes(int harmonics)
    : harmonics_(harmonics), samples_(harmonics <= 64 ? std::max(16, 8 * harmonics) : 4 * harmonics) {
  if (harmonics < 1) throw std::invalid_argument("trigonometric extremes: at least one harmonic");
  const auto m_count = static_cast<std::size_t>(samples_);
  cosine_.resize(m_count * static_cast<std::size_t>(harmonics));
  sine_.resize(cosine_.size());
  for (int k = 1; k <= harmonics; ++k)
    for (std::size_t m = 0; m < m_count; ++m) {
      // k m reduced modulo M keeps the angle below 2 pi, where sincos is exact to rounding.
      const auto km = (static_cast<std::size_t>(k) * m) % m_count;
      const double theta = 2 * std::numbers::pi * static_cast<double>(km) / static_cast<double>(m_count);
      cosine_[static_cast<std::size_t>(k - 1) * m_count + m] = std::cos(theta);
      sine_[static_cast<std::size_t>(k - 1) * m_count + m] = std::sin(theta);
    }
}

Extremes TrigonometricExtremes::operator()(std::span<const std::complex<double>> c, std::vector<double>& f) const {
  if (c.size() != static_cast<std::size_t>(harmonics_))
    throw std::invalid_argument("trigonometric extremes: one coefficient per harmonic");
  const auto m_count = static_cast<std::size_t>(samples_);
  f.resize(m_count);
  const double bound = sample(c, cosine_.data(), sine_.data(), f.data(), m_count);
  if (bound == 0) return {0, 0};
  const double h = 2 * std::numbers::pi / static_cast<double>(m_count);
  const double slack = bound * h * h / 8;
  const auto [low, high] = std::minmax_element(f.begin(), f.end());
  Extremes out{*low, *high};
  const double f_low = *low, f_high = *high;
  for (std::size_t m = 0; m < m_count; ++m) {
    // The neighbours on the circle, without a division by a count the compiler does not know
    // (two a sample were a quarter of this function's time).
    const double before = f[m == 0 ? m_count - 1 : m - 1], after = f[m + 1 == m_count ? 0 : m + 1];
    const bool greatest = f[m] >= before && f[m] >= after && f[m] >= f_high - slack;
    const bool least = f[m] <= before && f[m] <= after && f[m] <= f_low + slack;
    if (!greatest && !least) continue;
    // Newton starts at the vertex of the parabola through the three samples.
    const double theta = h * static_cast<double>(m), curvature = before - 2 * f[m] + after;
    const double start = curvature != 0 ? theta + std::clamp(0.5 * h * (before - after) / curvature, -0.5 * h, 0.5 * h) : theta;
    if (greatest) out.greatest = std::max(out.greatest, refine(c, theta, start, f[m], h, 1.0));
    if (least) out.least = std::min(out.least, refine(c, theta, start, f[m], h, -1.0));
  }
  return out;
}

}  // namespace hemotree
