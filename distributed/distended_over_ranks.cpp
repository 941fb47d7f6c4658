#include "distributed/distended_over_ranks.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include <mpi.h>

#include "distributed/steady_share.hpp"
#include "mpi/session.hpp"
#include "steady/distended_iteration.hpp"

namespace hemotree {

DistendedOverRanks solve_distended_steady_flow_over_ranks(const Network& net, const TreeCut& cut, const Blood& blood,
                                                         std::span<const TubeLaw> laws, const ViscosityTable& viscosity,
                                                         double inlet_flow, int threads) {
  DistendedOverRanks out;
  std::optional<SteadyShare> share;
  // What each rank sets up alone: its share, and its vessels' rigid resistances.
  on_every_rank([&] {
    share.emplace(net, cut, steady_rows(net), inlet_flow);
    out.nodes.assign(share->nodes().begin(), share->nodes().end());
    out.vessels.assign(share->vessels().begin(), share->vessels().end());
    out.nodes_by_label = out.nodes;
    std::sort(out.nodes_by_label.begin(), out.nodes_by_label.end());
    out.resistance.assign(net.vessel_count(), 0.0);
    for (const std::int32_t v : out.vessels)
      out.resistance[static_cast<std::size_t>(v)] = vessel_resistance(net, blood, static_cast<std::size_t>(v));
  });
  // A sweep's solve: the share's, with the sweep's resistances.
  auto solve = [&](const std::vector<double>& r, SteadyFlow& s) {
    share->solve(r, s);
    ++out.sweeps;
  };
  auto largest = [](double x) {
    double mine = std::isnan(x) ? -std::numeric_limits<double>::infinity() : x, all = mine;
    MPI_Allreduce(&mine, &all, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    return all == -std::numeric_limits<double>::infinity() ? std::numeric_limits<double>::quiet_NaN() : all;
  };
  const DistendedPart part{out.vessels, out.nodes, solve, largest, [](const std::function<void()>& step) { on_every_rank(step); }};
  out.flow = iterate_distended(net, blood, laws, viscosity, part, out.resistance, threads);
  out.traffic = share->traffic();
  return out;
}

}  // namespace hemotree
