// Under mpirun (ctest label mpi, 1 to 4 ranks): the linear periodic state of a grown tree (a
// half-sine inflow at its root, RCR outlets at its leaves, the mean shift forced in its
// largest vessels, or in those down to a tenth of the root's lumen, across a first cut) over the ranks (distributed/linear_periodic_over_ranks.hpp) gives each rank
// its share of the one-process solve_linear_periodic bit for bit: every own vessel's line,
// mean flow, middle amplitudes and shifted mean pressure, every own node's amplitudes and
// mean (a node no vessel reaches too); no forced vessel across the cut; every vessel forced
// (no top could hold them and leave every rank a vessel): PETSc's solve, within 1e-10 of the
// whole's. Exit 0 when every
// rank agrees. The periodic instant (a pulsatile run's start) over the ranks likewise.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include <mpi.h>

#include "core/errors.hpp"
#include "core/setting_error.hpp"
#include "distributed/linear_periodic_over_ranks.hpp"
#include "distributed/network_cut.hpp"
#include "../grown_trees.hpp"
#include "mpi/session.hpp"
#include "partition/partition.hpp"
#include "steady/vessel_laws.hpp"

using namespace hemotree;

namespace {

bool same(double a, double b) { return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b); }
bool same(std::complex<double> a, std::complex<double> b) { return same(a.real(), b.real()) && same(a.imag(), b.imag()); }

}  // namespace

int main(int argc, char** argv) {
  int failures = 0;
  {
    MpiSession session(argc, argv);
    const int ranks = world_size(), rank = world_rank();
    Waveform inflow;  // half sine, 1 s, 1 ul/min on average
    inflow.mean = 1e-9 / 60;
    Network net = test_networks::fed_tree(BoundaryType::rcr, inflow);
    net.add_node(net.node_id.back() + 1000);  // a node no vessel reaches (a file may list one)
    const Blood blood = net.blood.value_or(Blood{});
    const std::vector<TubeLaw> laws = vessel_laws(net, blood, 0.0, 0.1);
    const ViscosityTable viscosity(blood);
    const int harmonics = 6;
    const double root_area = blood.density / [&] {
      const SteadyFlow s = solve_distended_steady_flow(net, blood, laws, viscosity, inflow.mean_value(), nullptr);
      return loaded_line(net, blood, laws, viscosity, s, 0).inertance;
    }();
    // The mean shift forced in the vessels of more than a fraction of the root's lumen: 0.8,
    // the top's; 0.1, deep enough that a first cut over several ranks crosses them.
    // Each rank with two threads too (the two-ports of a solve and the lines built in
    // parallel): the same bits.
    for (const auto& [fraction, threads] : {std::pair{0.8, 1}, std::pair{0.1, 1}, std::pair{0.1, 2}}) {
      auto large = [&](const VesselLine& line) { return blood.density / line.inertance > fraction * root_area; };
      const LinearPeriodic whole = solve_linear_periodic(net, blood, laws, viscosity, harmonics, 1, large);
      const LinearPeriodicOverRanks mine =
          solve_linear_periodic_over_ranks(net, blood, laws, viscosity, harmonics, threads, large);
      std::size_t differ = 0, shifted = 0, across = 0;
      std::size_t kinds[5] = {0, 0, 0, 0, 0};
      for (const std::int32_t vessel : mine.vessels) {
        const auto v = static_cast<std::size_t>(vessel);
        const VesselLine &a = mine.periodic.line(v), &b = whole.line(v);
        kinds[0] += !same(a.resistance, b.resistance) + !same(a.compliance, b.compliance) + !same(a.kappa, b.kappa) +
                    !same(a.mean_velocity, b.mean_velocity);
        kinds[1] += !same(mine.periodic.mean_flow(v), whole.mean_flow()[v]);
        for (const double s : {0.0, 0.3, 0.5, 1.0}) kinds[2] += !same(mine.periodic.mean_pressure_at(v, s), whole.mean_pressure_at(v, s));
        for (int k = 1; k <= harmonics; ++k) {
          const VesselLine::Point p = mine.periodic.middle(k, v), q = whole.middle(k, v);
          kinds[3] += !same(p.pressure, q.pressure) + !same(p.flow, q.flow);
        }
        shifted += large(b);
      }
      bool lone = false;
      for (const std::int32_t node : mine.nodes) {
        const auto i = static_cast<std::size_t>(node);
        lone |= i + 1 == net.node_count();
        kinds[4] += !same(mine.periodic.mean_node_pressure(i), whole.mean_node_pressure()[i]);
        for (int k = 1; k <= harmonics; ++k) kinds[4] += !same(mine.periodic.node_pressure(k, i), whole.node_pressure(k, i));
      }
      for (const std::size_t k : kinds) differ += k;
      // No forced vessel crosses the cut: each lies on the top.
      for (int r = 0; r < ranks; ++r)
        if (r != mine.cut->top_rank)
          for (const std::int32_t root : mine.cut->roots[static_cast<std::size_t>(r)])
            across += large(whole.line(static_cast<std::size_t>(mine.cut->parent_edge[static_cast<std::size_t>(root)])));
      if (differ != 0 || mine.vessels.empty() || across != 0) {
        ++failures;
        std::fprintf(stderr,
                     "rank %d, %g of the root: %zu numbers not the whole's bits (%zu vessels; lines %zu, mean flows %zu, "
                     "mean pressures %zu, middles %zu, nodes %zu), %zu forced vessels across the cut\n",
                     rank, fraction, differ, mine.vessels.size(), kinds[0], kinds[1], kinds[2], kinds[3], kinds[4], across);
      }
      std::size_t counts[3] = {mine.vessels.size(), shifted, lone ? 1u : 0u}, all[3] = {0, 0, 0};
      MPI_Allreduce(counts, all, 3, MPI_UNSIGNED_LONG, MPI_SUM, MPI_COMM_WORLD);
      if (all[0] != net.vessel_count() || all[1] == 0 || all[2] != 1) {
        ++failures;
        std::fprintf(stderr, "rank %d: the ranks hold %zu vessels of %zu, %zu forced\n", rank, all[0], net.vessel_count(), all[1]);
      }
      if (rank == 0)
        std::printf("%g of the root's lumen, %d thread(s) a rank: %zu forced, the top's %zu vessels\n", fraction, threads, all[1],
                    mine.partition.top.size());
    }
    // The periodic instant (a pulsatile run's start) at t = 0.3 s, the vessels of more than a
    // tenth of the root's lumen kept (the run's 1D ones), the mean shifted: each rank's nodes'
    // pressures, vessels' middle flows and kept vessels' lines and amplitudes, the whole's bits.
    {
      std::vector<bool> keep(net.vessel_count(), false);
      const SteadyFlow s = solve_distended_steady_flow(net, blood, laws, viscosity, inflow.mean_value(), nullptr);
      for (std::size_t v = 0; v < keep.size(); ++v) keep[v] = blood.density / loaded_line(net, blood, laws, viscosity, s, v).inertance > 0.1 * root_area;
      const PeriodicInstant whole =
          solve_periodic_instant(net, blood, laws, viscosity, s, RunBoundaries(net), harmonics, 0.3, keep, 1, true);
      const PeriodicInstantOverRanks mine =
          solve_periodic_instant_over_ranks(net, blood, laws, viscosity, harmonics, 0.3, keep, 1, true);
      std::size_t differ = 0, kept = 0;
      for (const std::int32_t node : mine.nodes)
        differ += !same(mine.instant.node_pressure[static_cast<std::size_t>(node)], whole.node_pressure[static_cast<std::size_t>(node)]);
      for (const std::int32_t vessel : mine.vessels) {
        const auto v = static_cast<std::size_t>(vessel);
        differ += !same(mine.instant.middle_flow[v], whole.middle_flow[v]);
        if (!whole.along.holds(v)) continue;
        differ += !mine.instant.along.holds(v);
        if (!mine.instant.along.holds(v)) continue;
        ++kept;
        for (const double x : {0.0, 0.5, 1.0}) differ += !same(mine.instant.along.mean_pressure_at(v, x), whole.along.mean_pressure_at(v, x));
        for (int k = 1; k <= harmonics; ++k) {
          const VesselLine::Point p = mine.instant.along.middle(k, v), q = whole.along.middle(k, v);
          differ += !same(p.pressure, q.pressure) + !same(p.flow, q.flow);
        }
      }
      std::size_t kept_all = 0;
      MPI_Allreduce(&kept, &kept_all, 1, MPI_UNSIGNED_LONG, MPI_SUM, MPI_COMM_WORLD);
      if (differ != 0 || kept_all == 0) {
        ++failures;
        std::fprintf(stderr, "rank %d, the instant: %zu numbers not the whole's bits, %zu kept vessels in all\n", rank, differ,
                     kept_all);
      }
    }
    // Every vessel forced: over several ranks every vessel would be the top's, which leaves a
    // rank without one: each harmonic's system by PETSc instead (no cut), every own node's
    // amplitudes and mean and every own vessel's mean flow within 1e-10 of the whole's.
    if (ranks > 1) {
      auto every = [](const VesselLine&) { return true; };
      const LinearPeriodic whole = solve_linear_periodic(net, blood, laws, viscosity, 2, 1, every);
      const LinearPeriodicOverRanks mine = solve_linear_periodic_over_ranks(net, blood, laws, viscosity, 2, 1, every);
      double worst = 0;
      auto near = [&](std::complex<double> a, std::complex<double> b, double scale) {
        worst = std::max(worst, std::abs(a - b) / scale);
      };
      const double p_scale = *std::max_element(whole.mean_node_pressure().begin(), whole.mean_node_pressure().end());
      const double q_scale = std::abs(whole.mean_flow()[0]);
      for (const std::int32_t node : mine.nodes) {
        const auto i = static_cast<std::size_t>(node);
        near(mine.periodic.mean_node_pressure(i), whole.mean_node_pressure()[i], p_scale);
        for (int k = 1; k <= 2; ++k) near(mine.periodic.node_pressure(k, i), whole.node_pressure(k, i), p_scale);
      }
      for (const std::int32_t v : mine.vessels)
        near(mine.periodic.mean_flow(static_cast<std::size_t>(v)), whole.mean_flow()[static_cast<std::size_t>(v)], q_scale);
      if (mine.cut || !(worst <= 1e-10) || mine.solver.find("PETSc") == std::string::npos) {
        ++failures;
        std::fprintf(stderr, "rank %d, every vessel forced: %.3g from the whole's (%s)\n", rank, worst, mine.solver.c_str());
      }
    }
    int total = 0;
    MPI_Allreduce(&failures, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
    failures = total;
    if (rank == 0 && total == 0) std::printf("%d ranks: the whole linear periodic state's bits\n", ranks);
  }
  return failures == 0 ? 0 : 1;
}
