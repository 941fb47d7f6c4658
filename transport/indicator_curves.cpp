#include "transport/indicator_curves.hpp"

#include <cmath>
#include <limits>

namespace hemotree {

namespace {
constexpr double nan = std::numeric_limits<double>::quiet_NaN();
}

IndicatorCurves::IndicatorCurves(std::size_t vessels, double injected, double centre, bool step)
    : injected_(injected), centre_(centre), step_(step), arrival_(vessels, nan), peak_time_(vessels, nan),
      peak_(vessels, 0.0), previous_(vessels, 0.0), mass_(vessels, 0.0), moment_(vessels, 0.0) {}

void IndicatorCurves::add(std::size_t v, double t0, double t1, double c) {
  const double threshold = arrival_fraction * injected_;
  if (std::isnan(arrival_[v]) && c >= threshold) {
    const double before = previous_[v];
    arrival_[v] = c > before ? t0 + (t1 - t0) * (threshold - before) / (c - before) : t1;
  }
  if (c > peak_[v]) {
    peak_[v] = c;
    peak_time_[v] = t1;
  }
  previous_[v] = c;
  mass_[v] += c * (t1 - t0);
  moment_[v] += c * (t1 - t0) * 0.5 * (t0 + t1);
}

IndicatorCurves::Landmarks IndicatorCurves::landmarks(double now) const {
  Landmarks l;
  l.arrival = arrival_;
  l.peak_time = peak_time_;
  l.peak = peak_;
  l.mean_transit.resize(mass_.size());
  for (std::size_t v = 0; v < mass_.size(); ++v) {
    if (step_) {
      // The area above the rise to the plateau the vessel has reached (its last value: below
      // c0 where other inflows dilute it), once it has risen.
      l.mean_transit[v] = std::isnan(arrival_[v]) || !(previous_[v] > 0) ? nan : (now - centre_) - mass_[v] / previous_[v];
    } else {
      l.mean_transit[v] = mass_[v] > 0 ? moment_[v] / mass_[v] - centre_ : nan;
    }
  }
  return l;
}

std::vector<double> IndicatorCurves::state() const {
  std::vector<double> s;
  s.reserve(state_arrays * mass_.size());
  for (const auto* a : {&arrival_, &peak_time_, &peak_, &previous_, &mass_, &moment_}) s.insert(s.end(), a->begin(), a->end());
  return s;
}

std::vector<double> IndicatorCurves::state_of(std::span<const std::int32_t> vessels) const {
  std::vector<double> s;
  s.reserve(state_arrays * vessels.size());
  for (const auto* a : {&arrival_, &peak_time_, &peak_, &previous_, &mass_, &moment_})
    for (const std::int32_t v : vessels) s.push_back((*a)[static_cast<std::size_t>(v)]);
  return s;
}

bool IndicatorCurves::restore(std::span<const double> s) {
  const std::size_t n = mass_.size();
  if (s.size() != state_arrays * n) return false;
  std::size_t k = 0;
  for (auto* a : {&arrival_, &peak_time_, &peak_, &previous_, &mass_, &moment_}) {
    a->assign(s.begin() + static_cast<std::ptrdiff_t>(k), s.begin() + static_cast<std::ptrdiff_t>(k + n));
    k += n;
  }
  return true;
}

}  // namespace hemotree
