// The landmarks of an indicator-dilution curve in every vessel, gathered step by step over a
// run (the curves themselves would be vessels x steps): when the indicator arrives, when it
// peaks and how high, and its mean transit time (docs/transport.md, "Tracers").
//
// Per vessel, from its concentration c over each transport step [t0, t1]:
// - arrival: when c first reaches 1 % of the injected concentration (linear between steps);
// - peak and time to peak: the highest c and the end of the step that reached it;
// - mean transit time: for a bolus, the curve's first moment int t c dt / int c dt less the
//   bolus's centre (the impulse response's mean delay); for a step, int (1 - c / c_end) dt
//   from the step's start, c_end the vessel's last value (the area above the rise to its
//   plateau: the same mean delay once the plateau is reached). NaN where the curve holds no
//   indicator (or, for a step, has not arrived).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "core/array_bytes.hpp"

namespace hemotree {

class IndicatorCurves {
 public:
  // injected: the indicator's concentration while given; centre: the injection's centre
  // (bolus) or start (step).
  IndicatorCurves(std::size_t vessels, double injected, double centre, bool step);
  void add(std::size_t vessel, double t0, double t1, double concentration);

  struct Landmarks {
    std::vector<double> arrival, peak_time, peak, mean_transit;
  };
  // now: the time the run has reached (a step's area above the curve runs to it).
  Landmarks landmarks(double now) const;

  // The running sums, as a checkpoint keeps them: state_arrays arrays of one number a vessel,
  // one after the other.
  static constexpr std::size_t state_arrays = 6;
  std::vector<double> state() const;
  // The same numbers of these vessels alone: each array's, in turn, for them in their order
  // (what a rank holding some of the vessels sends of its state).
  std::vector<double> state_of(std::span<const std::int32_t> vessels) const;
  bool restore(std::span<const double> state);  // false for one of another size
  std::size_t bytes() const { return arrays_bytes(arrival_, peak_time_, peak_, previous_, mass_, moment_); }

  static constexpr double arrival_fraction = 0.01;

 private:
  double injected_, centre_;
  bool step_;
  std::vector<double> arrival_, peak_time_, peak_, previous_, mass_, moment_;
};

}  // namespace hemotree
