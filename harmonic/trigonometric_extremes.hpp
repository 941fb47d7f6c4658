// The least and the greatest value over a period of an oscillation given by its harmonics,
//
//   f(theta) = Re sum_{k=1}^{K} c_k e^{i k theta},   theta in [0, 2 pi),
//
// (a Fourier series without its mean: the systolic and diastolic excursions of a pressure,
// the peak and least of a flow). f is sampled at M = 8 K points (at least 16; 4 K beyond 64
// harmonics, where the table of M K cosines and sines grows large), h = 2 pi / M
// apart; each sample that is a local extreme of the samples and within S h^2 / 8 of the
// extreme sample (S = sum k^2 |c_k| bounds |f''|, so the sample nearest the true extreme is
// among them) is refined by Newton's method on f' = 0, from the vertex of the parabola
// through it and its neighbours and kept within h of it. The result is the polynomial's
// extreme to rounding where the refinement converges, and never short of the samples' own.
#pragma once

#include <complex>
#include <span>
#include <vector>

namespace hemotree {

struct Extremes {
  double least = 0, greatest = 0;
};

class TrigonometricExtremes {
 public:
  explicit TrigonometricExtremes(int harmonics);
  int harmonics() const { return harmonics_; }
  int samples() const { return samples_; }
  // c[k - 1] = c_k, k = 1 .. harmonics. scratch: the samples (any vector; one per thread).
  Extremes operator()(std::span<const std::complex<double>> c, std::vector<double>& scratch) const;

 private:
  int harmonics_, samples_;
  std::vector<double> cosine_, sine_;  // cos and sin of k theta_m, one row of samples per k
};

}  // namespace hemotree
