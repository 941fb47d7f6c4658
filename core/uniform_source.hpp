// A uniform draw in [0, 1) from the 53 high bits of std::mt19937_64, whose sequence the
// C++ standard fixes: the same seed gives the same tree (vgen) and the same pruning mask
// (vprune) with every standard library (std::uniform_real_distribution's algorithm, by
// contrast, is left to the implementation).
#pragma once

#include <cstdint>
#include <random>

namespace hemotree {

class UniformSource {
 public:
  explicit UniformSource(std::uint64_t seed) : engine_(seed) {}
  double operator()() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  double between(double lo, double hi) { return lo + (hi - lo) * (*this)(); }

 private:
  std::mt19937_64 engine_;
};

}  // namespace hemotree
