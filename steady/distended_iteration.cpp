#include "steady/distended_iteration.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>

#include "core/errors.hpp"
#include "core/parallel_errors.hpp"
#include "physics/poiseuille.hpp"

namespace hemotree {

SteadyFlow iterate_distended(const Network& net, const Blood& blood, std::span<const TubeLaw> laws,
                             const ViscosityTable& viscosity, const DistendedPart& part, std::vector<double>& r,
                             int threads) {
  const bool every_vessel = part.vessels.empty(), every_node = part.nodes.empty();
  const auto vessels = static_cast<std::int64_t>(every_vessel ? net.vessel_count() : part.vessels.size());
  const std::size_t nodes = every_node ? net.node_count() : part.nodes.size();
  auto vessel = [&](std::size_t k) { return every_vessel ? k : static_cast<std::size_t>(part.vessels[k]); };
  auto node = [&](std::size_t k) { return every_node ? k : static_cast<std::size_t>(part.nodes[k]); };
  SteadyFlow s, next;
  part.solve(r, s);
  // Each sweep's resistances are blended with the last ones, r <- (1 - w) r + w R(p(r)): the
  // iteration alternates (a higher pressure widens the lumens, which lowers it), and w = 1/2
  // damps that, each sweep then halving the change (27 sweeps on the 5301-vessel tree). From
  // the third sweep w follows the map's own slope L, read off two changes made at one w
  // (ratio = 1 - w + w L): w = 1 / (1 - L) cancels it to first order, within [0.1, 1] (9
  // sweeps there; a growing change halves w).
  double blend = 0.5, last_blend = 0, last_change = 0;
  for (int sweep = 0; sweep < 200; ++sweep) {
    part.on_every_part([&] {
      // Every vessel's own numbers, in parallel blocks: the same for any count of threads (a
      // collapsing lumen's message, the lowest vessel's).
      parallel_blocks(vessels, threads, [&](std::int64_t first, std::int64_t last) {
        for (auto k = static_cast<std::size_t>(first); k < static_cast<std::size_t>(last); ++k) {
          const std::size_t v = vessel(k);
          const double p = 0.5 * (s.node_pressure[net.from[v]] + s.node_pressure[net.to[v]]);
          const double area = laws[v].area(p);
          if (!(area > 0))
            throw InputError("vessel " + std::to_string(net.id[v]) + ": the lumen collapses in steady flow");
          const double diameter = std::sqrt(4 / std::numbers::pi * area);
          r[v] = (1 - blend) * r[v] + blend * poiseuille_resistance(viscosity(area), net.length[v], diameter, blood.alpha);
        }
      });
    });
    part.solve(r, next);
    double change = 0;  // over the nodes that have a pressure (a node no vessel reaches has none)
    for (std::size_t k = 0; k < nodes; ++k)
      if (const double d = std::abs(next.node_pressure[node(k)] - s.node_pressure[node(k)]); d > change) change = d;
    change = part.largest(change);
    std::swap(s, next);
    // Relative to the inlet's pressure, or where boundaries at nodes drive the network (no
    // inlet), to the largest node pressure (such a network, the rat mesentery, took all 200
    // sweeps before: 12 now).
    double scale = part.largest(std::abs(s.inlet_pressure));
    if (!(scale > 0)) {
      scale = 0;
      for (std::size_t k = 0; k < nodes; ++k)
        if (const double p = std::abs(s.node_pressure[node(k)]); p > scale) scale = p;
      scale = part.largest(scale);
    }
    if (change <= 1e-9 * scale) break;
    // The ratio of two changes made at one blend gives the slope; a change of blend waits a sweep.
    if (last_change > 0 && last_blend == blend) {
      const double ratio = change / last_change, slope = (ratio - (1 - blend)) / blend;
      last_blend = blend;
      blend = ratio >= 1 ? std::max(0.1, 0.5 * blend) : std::clamp(1 / (1 - std::min(slope, 0.0)), 0.1, 1.0);
    } else {
      last_blend = blend;
    }
    last_change = change;
  }
  return s;
}

}  // namespace hemotree
