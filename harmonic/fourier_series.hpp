// A periodic boundary value as its Fourier series, f(t) = Re sum_{k=0}^{K} F_k e^{i k w t},
// w = 2 pi / T: F_0 the mean, F_k (k >= 1) twice the k-th coefficient of the discrete
// Fourier transform of M equally spaced samples over one period (the trapezoidal rule, exact
// for trigonometric polynomials of degree below M / 2; a half-sine's kink leaves its
// coefficients an error of O(M^-2)).
#pragma once

#include <complex>
#include <numbers>
#include <vector>

#include "formats/boundary_conditions.hpp"

namespace hemotree {

struct FourierSeries {
  double period = 1.0;                           // T [s]
  std::vector<std::complex<double>> amplitude;  // F_0 .. F_K

  double omega(int k) const { return 2 * std::numbers::pi * k / period; }
  double operator()(double t) const {
    double f = amplitude.empty() ? 0.0 : amplitude[0].real();
    for (std::size_t k = 1; k < amplitude.size(); ++k)
      f += (amplitude[k] * std::polar(1.0, omega(static_cast<int>(k)) * t)).real();
    return f;
  }
};

// The first K harmonics of a waveform from M samples (M > 2 K; 4096 resolves a half-sine's
// first 20 to 1e-6 of its peak).
inline FourierSeries fourier_series(const Waveform& wave, int harmonics, int samples = 4096) {
  FourierSeries s;
  s.period = wave.shape == Waveform::Shape::constant ? 1.0 : wave.period;
  s.amplitude.assign(static_cast<std::size_t>(harmonics) + 1, 0.0);
  if (wave.shape == Waveform::Shape::constant) {
    s.amplitude[0] = wave.mean;
    return s;
  }
  for (int m = 0; m < samples; ++m) {
    const double t = s.period * m / samples, f = wave(t);
    // e^{-2 pi i k m / M} by powers of its k = 1 value: K products, rounding K times 1e-16.
    const std::complex<double> step = std::polar(1.0, -2 * std::numbers::pi * m / samples);
    std::complex<double> e = 1.0;
    for (int k = 0; k <= harmonics; ++k, e *= step) s.amplitude[static_cast<std::size_t>(k)] += f * e;
  }
  for (int k = 0; k <= harmonics; ++k) s.amplitude[static_cast<std::size_t>(k)] *= (k == 0 ? 1.0 : 2.0) / samples;
  return s;
}

}  // namespace hemotree
