// Womersley waves: see womersley.hpp.
#include "physics/womersley.hpp"

#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>

#include "core/errors.hpp"

namespace hemotree {

namespace {

using Complex = std::complex<double>;
using ComplexL = std::complex<long double>;

// Largest |z| summed by the power series. Its largest term is about e^|z| / (2 pi |z|); the
// long double sum (64-bit mantissa) keeps the cancellation error near 1e-16 relative for
// complex arguments such as i^(3/2) x, and near 1e-16 * e^|z| / |J_n| absolute for real ones.
constexpr double series_limit = 20;

ComplexL series_j(int n, ComplexL z) {
  const ComplexL half = z / 2.0L;
  const ComplexL half2 = half * half;
  ComplexL term = n == 0 ? ComplexL(1) : half;  // k = 0: (z/2)^n / n!
  ComplexL sum = term;
  for (int k = 1; k < 500; ++k) {
    term *= -half2 / static_cast<long double>(k * (k + n));
    sum += term;
    if (std::norm(term) <= 1e-34L * std::norm(sum)) break;  // |term| <= 1e-17 |sum|, without hypotl
  }
  return sum;
}

// Hankel's expansion, valid for |arg z| < pi; used for Re z >= 0 only (J_n(-z) = (-1)^n J_n(z)).
// J_n(z) ~ sqrt(2 / (pi z)) (P cos chi - Q sin chi), chi = z - n pi / 2 - pi / 4, with
// P = sum_k (-1)^k a_2k / z^2k, Q = sum_k (-1)^k a_(2k+1) / z^(2k+1),
// a_k = (4n^2 - 1)(4n^2 - 9)...(4n^2 - (2k-1)^2) / (k! 8^k) (Abramowitz & Stegun 9.2.5-10).
struct HankelSums {
  Complex p, q;
};

HankelSums hankel_sums(int n, Complex z) {
  const double mu = 4.0 * n * n;
  HankelSums sums{1.0, 0.0};
  Complex term = 1.0;  // a_k / z^k, k = 0
  double previous = 1.0;
  for (int k = 1; k < 200; ++k) {
    const double odd = 2.0 * k - 1;
    term *= (mu - odd * odd) / (k * 8.0) / z;
    const double size = std::abs(term);
    if (size > previous) break;  // asymptotic series: stop at the smallest term
    previous = size;
    // (-1)^floor(k/2): k = 1, 2 -> +1 for Q, -1 for P; k = 3, 4 -> -1, +1; ...
    const double sign = (k / 2) % 2 == 0 ? 1.0 : -1.0;
    if (k % 2 == 0) sums.p += sign * term; else sums.q += sign * term;
    if (size < 1e-17) break;
  }
  return sums;
}

Complex hankel_j(int n, Complex z) {
  const HankelSums s = hankel_sums(n, z);
  const Complex chi = z - (n * 0.5 + 0.25) * std::numbers::pi;
  return std::sqrt(2.0 / (std::numbers::pi * z)) * (s.p * std::cos(chi) - s.q * std::sin(chi));
}

// J1(z) / J0(z) from Hankel's expansion for Re z >= 0, without J0 or J1 themselves (which
// overflow for |Im z| above ~700): with chi = z - pi/4, chi_1 = chi - pi/2, so
// J1 / J0 = (P1 sin chi + Q1 cos chi) / (P0 cos chi - Q0 sin chi) = (P1 t + Q1) / (P0 - Q0 t),
// t = tan chi, which stays bounded (-> +-i) as |Im z| grows.
Complex hankel_ratio(Complex z) {
  const HankelSums s0 = hankel_sums(0, z);
  const HankelSums s1 = hankel_sums(1, z);
  const Complex t = std::tan(z - 0.25 * std::numbers::pi);
  return (s1.p * t + s1.q) / (s0.p - s0.q * t);
}

// 1 - F10(z) = (z J0 - 2 J1) / (z J0). Beyond series_limit, from hankel_ratio, so any W
// works. For |z| <= series_limit the numerator is summed as its
// own series z sum_k (-1)^k (z/2)^(2k) k / (k!^2 (k+1)), free of the cancellation of
// 1 - F10 for small z.
Complex one_minus_f10(Complex zd) {
  if (std::abs(zd) > series_limit) {
    // F10 is even in z (J1 odd, J0 even): evaluate it at the argument with Re >= 0.
    const Complex u = zd.real() >= 0 ? zd : -zd;
    return 1.0 - 2.0 * hankel_ratio(u) / u;
  }
  const ComplexL z(zd.real(), zd.imag());
  const ComplexL half2 = z * z / 4.0L;
  ComplexL power = 1;  // (-1)^k (z/2)^(2k) / k!^2
  ComplexL numerator = 0;
  for (int k = 1; k < 500; ++k) {
    power *= -half2 / static_cast<long double>(k * k);
    const ComplexL term = power * static_cast<long double>(k) / static_cast<long double>(k + 1);
    numerator += term;
    if (std::norm(term) <= 1e-34L * std::norm(numerator)) break;
  }
  const ComplexL result = numerator / series_j(0, z);
  return {static_cast<double>(result.real()), static_cast<double>(result.imag())};
}

void require_positive(double value, const char* name) {
  if (!(std::isfinite(value) && value > 0)) {
    std::ostringstream message;
    message << name << " must be finite and > 0, got " << value;
    throw InputError(message.str());
  }
}

}  // namespace

Complex bessel_j(int n, Complex z) {
  if (n != 0 && n != 1) throw std::domain_error("bessel_j: only n = 0 and n = 1 are implemented");
  if (!std::isfinite(z.real()) || !std::isfinite(z.imag()))
    throw std::domain_error("bessel_j: non-finite argument");
  Complex result;
  if (std::abs(z) <= series_limit) {
    const ComplexL sum = series_j(n, ComplexL(z.real(), z.imag()));
    result = {static_cast<double>(sum.real()), static_cast<double>(sum.imag())};
  } else if (z.real() >= 0) {
    result = hankel_j(n, z);
  } else {
    result = (n == 0 ? 1.0 : -1.0) * hankel_j(n, -z);
  }
  if (!std::isfinite(result.real()) || !std::isfinite(result.imag()))
    throw std::domain_error("bessel_j: result overflows double");
  return result;
}

double womersley_number(double diameter, double density, double viscosity, double omega) {
  require_positive(diameter, "womersley_number: diameter");
  require_positive(density, "womersley_number: density");
  require_positive(viscosity, "womersley_number: viscosity");
  require_positive(omega, "womersley_number: omega");
  return diameter / 2 * std::sqrt(density * omega / viscosity);
}

WomersleyWave womersley_wave(double elastic_speed, double womersley, double omega) {
  require_positive(elastic_speed, "womersley_wave: elastic speed");
  require_positive(womersley, "womersley_wave: Womersley number");
  require_positive(omega, "womersley_wave: omega");
  const double w = womersley;
  Complex denominator;  // 1 - F10
  if (w < 1e-3) {
    // With z = i^(3/2) W, z^2 = -i W^2: J0 = 1 - z^2/4 + ..., 2 J1 / z = 1 - z^2/8 + z^4/192,
    // so 1 - F10 = -(z^2/8)(1 + z^2/6 + O(z^4)) = (i W^2 / 8)(1 - i W^2 / 6).
    // Leading order: k = (omega/c_ref) sqrt(8 / (i W^2)) = (omega/c_ref)(2 sqrt 2 / W) e^(-i pi/4)
    //              = (omega/c_ref)(2 / W)(1 - i),
    // hence Re k = 2 omega / (W c_ref), c = omega / Re k = W c_ref / 2 exactly (the factor is
    // 1, not sqrt 2: the sqrt 2 of |k| cancels against cos(pi/4)), and gamma = 2 pi.
    denominator = Complex(0, w * w / 8) * Complex(1, -w * w / 6);
  } else {
    const Complex z = std::polar(w, 0.75 * std::numbers::pi);  // i^(3/2) W
    denominator = one_minus_f10(z);
  }
  // Principal square root: Re >= 0, so Re k > 0 as required.
  const Complex k = omega / elastic_speed * std::sqrt(1.0 / denominator);
  return {omega / k.real(), -2 * std::numbers::pi * k.imag() / k.real(), k};
}

}  // namespace hemotree
