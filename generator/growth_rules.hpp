// The rules of stochastic growth (the paper's Table 2 with ERRATA.md, Table 1's wall
// thickness ratios and an E(D) table), as a value that reads from and writes to JSON so
// that users can replace any of it with `vgen --rules FILE`.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "formats/network.hpp"
#include "generator/fractal_length.hpp"

namespace hemotree {

// Vessel length as a function of its diameter.
struct LengthLaw {
  enum class Kind { power, uniform } kind = Kind::power;
  // power: l = zeta r^gamma, r = D/2 in metres; zeta given or computed from a calibration
  double gamma = 1.0;
  double zeta = 0.0;
  std::optional<FractalCalibration> calibration;  // when present, zeta was computed from it
  // uniform: l ~ U[min, max] (capillaries)
  double min = 0.0, max = 0.0;
};

// The branching rule for parents whose diameter lies in [diameter_min, diameter_max):
// D1 = kappa D_p with kappa ~ U[kappa_min, kappa_max], D2 = (1 - kappa^m)^(1/m) D_p.
// The length law applies to vessels whose own diameter lies in the range.
struct BranchingRange {
  double diameter_min = 0.0, diameter_max = 0.0;  // [m]
  double kappa_min = 0.0, kappa_max = 0.0;
  double murray_exponent = 3.0;                   // m
  LengthLaw length;
};

// Wall thickness h as a function of diameter, chosen per vessel class.
struct WallLaw {
  enum class Kind { ratio, exponential } kind = Kind::ratio;
  double h_over_d = 0.1;  // ratio: h = h_over_d D
  // exponential: h = R (a e^(b R) + c e^(d R)), R = D/2 in metres
  double a = 0, b = 0, c = 0, d = 0;
  double thickness(double diameter) const;
};

// When a vessel stops branching.
enum class StopRule {
  smaller_daughter,  // it branches only if both daughters would be at least D_min
  mean_daughter,     // it branches if its daughters' mean diameter would be at least D_min
  larger_daughter,   // it branches if its larger daughter would be at least D_min
  parent             // it branches while its own diameter is at least D_min
};

struct GrowthRules {
  std::vector<BranchingRange> ranges;  // sorted by diameter, contiguous, no overlap
  std::array<WallLaw, vessel_class_count> wall;
  // Young's modulus E(D): piecewise linear through the knots, constant beyond the ends.
  std::vector<double> modulus_diameter, modulus_value;  // [m], [Pa]
  StopRule stop = StopRule::mean_daughter;

  const BranchingRange& range_for(double diameter) const;  // InputError when outside
  double youngs_modulus(double diameter) const;
};

// Table 2 with the errata: zeta from the Kamiya-Takahashi calibrations (104.07 proximal,
// 1458.6 distal); in the 500-100 um row gamma = 1.25 and so m = d_f + gamma = 3
// (docs/tree-statistics.md says why); growth stops by the mean-daughter rule.
GrowthRules default_rules();

// Throws InputError naming the problem (kappa outside (0, 1), gaps or overlaps, ...).
void validate(const GrowthRules& rules);

nlohmann::json to_json(const GrowthRules& rules);
GrowthRules rules_from_json(const nlohmann::json& j);  // validated; InputError on problems
GrowthRules read_rules(const std::string& path);

std::string_view to_string(StopRule rule);

}  // namespace hemotree
