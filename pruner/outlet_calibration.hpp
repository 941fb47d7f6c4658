// Outlets that stand exactly for what pruning removed (the paper's "Boundary conditions"):
// every removed subtree is reduced to its steady resistance (Poiseuille with the blood's
// apparent viscosity, series and parallel, down to the full tree's leaves) and its
// compliance (the sum of its vessels' dV/dp), and becomes an RCR outlet on a terminal vessel
// of at least 100 um, an R outlet on a thinner one.
#pragma once

#include <cstddef>
#include <string>

#include <nlohmann/json.hpp>

#include "core/setting_error.hpp"
#include "formats/network.hpp"
#include "pruner/pruning_strategies.hpp"

namespace hemotree {

struct OutletParameters {
  double venous_pressure = 10 * 133.322;         // p_out of every outlet [Pa]
  double capillary_pressure_drop = 5 * 133.322;  // mean drop across a leaf's outlet [Pa]
  double external_pressure = 10 * 133.322;       // interstitial p_ext for the wall laws [Pa]
  double rcr_min_diameter = 100e-6;              // [m]
  double thick_wall_ratio = 0.1;                 // h/D above which a wall is thick
};

// The resistance from every leaf of the full tree (a capillary) to the venous pressure.
// All leaves get the same R_cap; since their flows add up to the inflow whatever R_cap is,
// R_cap = drop * leaves / mean_inflow makes the mean drop across them exactly `drop`.
double capillary_outlet_resistance(std::size_t leaves, double mean_inflow, double drop);

struct OutletReport {
  double capillary_resistance = 0;
  std::size_t rcr = 0, resistance = 0, leaf = 0;  // outlets by kind (leaf: a full-tree leaf)
  std::size_t r1_limited = 0;  // RCR whose rho c / A exceeded the subtree resistance
  double steady_inlet_pressure_full = 0;    // [Pa]
  double steady_inlet_pressure_pruned = 0;  // [Pa]
};
nlohmann::json to_json(const OutletReport& report);

// Gives the full tree its leaf outlets, then the pruned network (extract(full, keep)) its
// outlets, blood and inlet, and solves both steadily: report holds both inlet pressures.
// full must be a rooted tree with blood and inlet set; pruned's vessels are full's kept ones
// in order.
OutletReport calibrate_outlets(Network& full, const KeepMask& keep, Network& pruned,
                               const OutletParameters& parameters);

// Steady arterial pressures lie within 0 to 300 mmHg. When the full tree's steady inlet
// pressure leaves that range, a warning naming the value in mmHg and the likely cause: an
// inflow (the setting mean_flow) meant for a tree of another size, with the inflow that gives
// about 100 mmHg (the drop down the tree is nearly proportional to it: within 2 %, since the
// capillary outlets' resistance follows the flow); "" when it is in range. The settings
// (mean_flow, venous_pressure, capillary_drop) are named in words (vprune: its flags).
std::string unphysiological_pressure_warning(const OutletReport& report,
                                             const OutletParameters& parameters,
                                             double mean_inflow, double root_diameter,
                                             const SettingWords& words = {});

}  // namespace hemotree
