#include "pruner/outlet_calibration.hpp"

#include <algorithm>
#include <string>

#include "core/errors.hpp"
#include "core/units.hpp"
#include "formats/topology.hpp"
#include "physics/wall_law.hpp"
#include "steady/steady_flow.hpp"

namespace hemotree {

double capillary_outlet_resistance(std::size_t leaves, double mean_inflow, double drop) {
  if (!(mean_inflow > 0)) throw InputError("the mean inflow must be positive");
  return drop * static_cast<double>(leaves) / mean_inflow;
}

nlohmann::json to_json(const OutletReport& r) {
  return {{"capillary_outlet_resistance", r.capillary_resistance},
          {"rcr_outlets", r.rcr},
          {"r_outlets", r.resistance},
          {"leaf_outlets", r.leaf},
          {"rcr_with_limited_r1", r.r1_limited},
          {"steady_inlet_pressure_full", r.steady_inlet_pressure_full},
          {"steady_inlet_pressure_pruned", r.steady_inlet_pressure_pruned}};
}

OutletReport calibrate_outlets(Network& full, const KeepMask& keep, Network& pruned,
                               const OutletParameters& p) {
  if (!full.blood || !full.inlet) throw std::logic_error("calibrate_outlets needs blood and inlet");
  const Blood& blood = *full.blood;
  const std::size_t n = full.vessel_count();
  const std::size_t root = check_rooted_tree(full);
  const Children children = children_of(full);
  auto is_leaf = [&](std::size_t v) { return children.offset[v] == children.offset[v + 1]; };

  OutletReport report;
  std::size_t leaves = 0;
  for (std::size_t v = 0; v < n; ++v) leaves += is_leaf(v);
  report.capillary_resistance = capillary_outlet_resistance(
      leaves, full.inlet->waveform.mean_value(), p.capillary_pressure_drop);

  // The full tree ends in its capillary outlets.
  Outlet leaf_outlet;
  leaf_outlet.type = BoundaryType::resistance;
  leaf_outlet.r = report.capillary_resistance;
  leaf_outlet.p_out = p.venous_pressure;
  full.outlets.clear();
  full.outlets.reserve(leaves);
  for (std::size_t v = 0; v < n; ++v)
    if (is_leaf(v)) {
      leaf_outlet.vessel = static_cast<std::int32_t>(v);
      full.outlets.push_back(leaf_outlet);
    }

  // One reduction of the full tree gives both its steady inlet pressure and, for every
  // vessel, the resistance of everything beyond it.
  const std::vector<double> resistance = vessel_resistances(full, blood);
  std::vector<Equivalent> beyond;
  report.steady_inlet_pressure_full =
      solve_steady_flow(full, resistance, full.inlet->waveform.mean_value(), &beyond).inlet_pressure;

  // Compliance beyond each vessel's distal node: dV/dp = 2 l sqrt(A_ref) / beta per vessel.
  std::vector<double> compliance_beyond(n, 0.0);
  std::vector<TubeLaw> laws(n);
  for (std::size_t v = 0; v < n; ++v) {
    laws[v] = tube_law({full.diameter[v], full.wall_thickness[v], full.youngs_modulus[v]},
                       p.external_pressure, p.thick_wall_ratio);
    laws[v].density = blood.density;
  }
  const std::vector<std::int32_t> order = breadth_first_order(children, root);
  for (auto it = order.rbegin(); it != order.rend(); ++it) {
    const auto v = static_cast<std::size_t>(*it);
    for (auto k = children.offset[v]; k < children.offset[v + 1]; ++k) {
      const auto d = static_cast<std::size_t>(children.index[k]);
      compliance_beyond[v] += full.length[d] * laws[d].compliance_per_length(laws[d].reference_area) +
                              compliance_beyond[d];
    }
  }

  // The pruned network: vessel k is the k-th kept vessel of the full tree.
  std::vector<std::int32_t> full_index;
  full_index.reserve(pruned.vessel_count());
  for (std::size_t v = 0; v < n; ++v)
    if (keep[v]) full_index.push_back(static_cast<std::int32_t>(v));
  if (full_index.size() != pruned.vessel_count())
    throw std::logic_error("pruned network does not match the keep mask");
  const Children pruned_children = children_of(pruned);

  pruned.outlets.clear();
  for (std::size_t k = 0; k < pruned.vessel_count(); ++k) {
    if (pruned_children.offset[k] != pruned_children.offset[k + 1]) continue;
    const auto f = static_cast<std::size_t>(full_index[k]);
    Outlet o;
    o.vessel = static_cast<std::int32_t>(k);
    o.p_out = p.venous_pressure;
    if (is_leaf(f)) {
      o.type = BoundaryType::resistance;
      o.r = report.capillary_resistance;
      ++report.leaf;
    } else if (full.diameter[f] >= p.rcr_min_diameter) {
      // R1 matches the terminal vessel's characteristic impedance, so waves leave without
      // reflection; R1 + R2 is the removed subtree's resistance, C its compliance.
      const TubeLaw& law = laws[f];
      const double area = law.reference_area;
      const double impedance = blood.density * law.wave_speed(area) / area;
      o.type = BoundaryType::rcr;
      o.r1 = std::min(impedance, beyond[f].resistance);
      o.r2 = beyond[f].resistance - o.r1;
      o.c = compliance_beyond[f];
      report.r1_limited += impedance > beyond[f].resistance;
      ++report.rcr;
    } else {
      o.type = BoundaryType::resistance;
      o.r = beyond[f].resistance;
      ++report.resistance;
    }
    pruned.outlets.push_back(o);
  }
  pruned.blood = full.blood;
  pruned.inlet = full.inlet;

  report.steady_inlet_pressure_pruned = solve_steady_flow(pruned).inlet_pressure;
  return report;
}

std::string unphysiological_pressure_warning(const OutletReport& report,
                                             const OutletParameters& p, double mean_inflow,
                                             double root_diameter, const SettingWords& words) {
  const auto named = [&](const char* setting) { return in_words(placeholder(setting), words); };
  constexpr double lowest = 0.0, highest = 300 * pascal_per_mmhg, typical = 100 * pascal_per_mmhg;
  const double inlet = report.steady_inlet_pressure_full;
  if (inlet >= lowest && inlet <= highest) return "";
  std::string text = "the steady inlet pressure is " + format_quantity(inlet, "mmHg") +
                     ", outside the physiological 0 to 300 mmHg: ";
  if (inlet < lowest)
    return text + named("venous_pressure") + " (" + format_quantity(p.venous_pressure, "mmHg") +
           ") is likely too low";
  // The capillary outlets always take `drop` on average; the rest is Poiseuille, nearly
  // linear in the flow.
  const double fixed = p.venous_pressure + p.capillary_pressure_drop;
  if (fixed > highest)
    return text + named("venous_pressure") + " (" + format_quantity(p.venous_pressure, "mmHg") + ") and " +
           named("capillary_drop") + " (" + format_quantity(p.capillary_pressure_drop, "mmHg") +
           ") alone exceed it";
  text += named("mean_flow") + " (" + format_quantity(mean_inflow, "ml/min") +
          ") is likely too large for a tree whose root is " +
          format_quantity(root_diameter, "um") + " wide";
  if (inlet > fixed && typical > fixed)
    text += " (about " + format_quantity(mean_inflow * (typical - fixed) / (inlet - fixed), "ml/min") +
            " gives 100 mmHg)";
  return text;
}

}  // namespace hemotree
