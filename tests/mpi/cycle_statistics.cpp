// Under mpirun (ctest label mpi, 1 to 4 ranks): a cycle's statistics over ranks
// (solver/cycle_over_ranks.hpp): each rank samples the vessels it steps; at the cycle's close
// rank 0 holds every vessel's results, the 1D vessels' wave speeds, every boundary's mean
// flow, the in- and outflow, the volume change and the mass balance with the bits of the
// one-process run's statistics (which every rank also takes here, alone); and the probes,
// each sampled by the rank that steps its vessel, give rank 0 the one-process probes.csv rows;
// every other rank keeps its own vessels' results alone, by entry. Exit 0 when every
// rank agrees, 1 otherwise, one line per failure on stderr.
#include <cstdint>
#include <cstdio>
#include <span>
#include <string>
#include <vector>

#include <mpi.h>

#include "pulse/pulse_solver.hpp"
#include "rank_checks.hpp"
#include "tree_with_waves.hpp"
#include "solver/cycle_over_ranks.hpp"
#include "solver/cycle_statistics.hpp"
#include "solver/probes_over_ranks.hpp"
#include "solver/pulse_ranks_mpi.hpp"

using namespace hemotree;
using rank_checks::check;
using rank_checks::rank;

using test_networks::same_bits;

int main(int argc, char** argv) {
  const int ranks = rank_checks::start(&argc, &argv);
  {
    const Network net = test_networks::tree_with_waves();
    const SolverOptions options = test_networks::options_over_ranks();
    PulseSolver whole(net, options);
    MpiPulseRanks over_ranks(net, std::vector<double>(net.vessel_count(), 1.0));
    PulseSolver mine(net, options, &over_ranks.ranks());
    const double frequency = 1 / whole.period();
    CycleStatistics whole_stats(net, whole, frequency), stats(net, mine, frequency);
    whole_stats.begin(whole);
    stats.begin(mine);
    // Probes too: the root, a 1D vessel's end, 0D vessels deep in the tree, one twice.
    const std::vector<Probe> probes = {{0, net.id[0], 0.5}, {net.vessel_count() - 1, net.id[net.vessel_count() - 1], 0.25},
                                       {net.vessel_count() / 2, net.id[net.vessel_count() / 2], 1.0},
                                       {0, net.id[0], 0.5}, {7, net.id[7], 0.0}};
    ProbeRecorder whole_probes(probes), gathered(probes);
    ProbesOverRanks probes_here(probes, mine);
    for (int n = 0; n < 30; ++n) {
      whole.step();
      mine.step();
      whole_stats.sample(whole, whole.time(), whole.dt());
      stats.sample(mine, mine.time(), mine.dt());
      if (n % 3 == 0) {
        whole_probes.sample(whole);
        probes_here.sample(mine);
      }
    }
    probes_here.gather_into(gathered);
    if (rank == 0)
      check(gathered.rows() == whole_probes.rows() && !gathered.rows().empty(),
            "the probes' rows differ from the whole run's:\n" + gathered.rows().substr(0, 300) + "\n" + whole_probes.rows().substr(0, 300));
    const CycleSummary a = whole_stats.close(whole), own = stats.close(mine);
    // The rows a block of 7 vessels at a time (the run's blocks are 65,536 vessels: this
    // tree would be one), as a cycle end writes them into the lead's snapshot: in the
    // vessels' order, each block after the last, each row the whole run's results.
    std::size_t next = 0, blocks = 0, rows_differ = 0;
    bool in_order = true;
    gather_cycle_rows(net, mine, own, stats.entry_vessels(mine), [&](std::size_t first, std::span<const double> rows) {
      in_order = in_order && first == next && rows.size() % cycle_row_width == 0 && rows.size() <= 7 * cycle_row_width &&
                 !rows.empty();
      next = first + rows.size() / cycle_row_width;
      ++blocks;
      for (std::size_t k = 0; k * cycle_row_width < rows.size() && first + k < a.vessels.size(); ++k) {
        const double* f = rows.data() + k * cycle_row_width;
        const VesselCycle& x = a.vessels[first + k];
        const WaveSpeeds w = a.wave_speeds(first + k);
        rows_differ += !same_bits(f[0], x.mean_flow) + !same_bits(f[1], x.mean_pressure) +
                       !same_bits(f[2], x.systolic_pressure) + !same_bits(f[3], x.diastolic_pressure) +
                       !same_bits(f[4], x.peak_flow) + !same_bits(f[5], x.least_flow) + !same_bits(f[6], x.mean_wss) +
                       !same_bits(f[7], x.reynolds) + !same_bits(f[8], w.pressure) + !same_bits(f[9], w.velocity);
      }
    }, 7);
    if (rank == 0)
      check(in_order && next == net.vessel_count() && blocks == (net.vessel_count() + 6) / 7 && rows_differ == 0,
            "the rows in blocks of 7: " + std::to_string(blocks) + " blocks to vessel " + std::to_string(next) + ", " +
                std::to_string(rows_differ) + " numbers unlike the whole run's");
    CycleSummary b = own;
    gather_cycle_vessels(net, mine, b, stats.entry_vessels(mine));
    if (rank == 0) {
      std::size_t differ = 0;
      check(b.vessels.size() == a.vessels.size(), "the vessels' results of " + std::to_string(b.vessels.size()) + " vessels");
      for (std::size_t v = 0; v < a.vessels.size() && v < b.vessels.size(); ++v) {
        const VesselCycle &x = a.vessels[v], &y = b.vessels[v];
        differ += !same_bits(x.mean_flow, y.mean_flow) + !same_bits(x.mean_pressure, y.mean_pressure) +
                  !same_bits(x.systolic_pressure, y.systolic_pressure) + !same_bits(x.diastolic_pressure, y.diastolic_pressure) +
                  !same_bits(x.peak_flow, y.peak_flow) + !same_bits(x.least_flow, y.least_flow) + !same_bits(x.mean_wss, y.mean_wss) +
                  !same_bits(x.reynolds, y.reynolds);
      }
      check(differ == 0, std::to_string(differ) + " vessel results differ from the whole run's");
      check(a.waves.size() == b.waves.size() && !a.waves.empty(), "the wave speeds of " + std::to_string(b.waves.size()) + " vessels");
      for (std::size_t k = 0; k < a.waves.size() && k < b.waves.size(); ++k)
        check(a.waves[k].first == b.waves[k].first && same_bits(a.waves[k].second.pressure, b.waves[k].second.pressure) &&
                  same_bits(a.waves[k].second.velocity, b.waves[k].second.velocity),
              "the wave speeds of vessel " + std::to_string(a.waves[k].first));
      check(a.boundary_mean_flow.size() == b.boundary_mean_flow.size(), "the boundaries' mean flows");
      std::size_t flows = 0;
      for (std::size_t k = 0; k < a.boundary_mean_flow.size() && k < b.boundary_mean_flow.size(); ++k)
        flows += !same_bits(a.boundary_mean_flow[k], b.boundary_mean_flow[k]);
      check(flows == 0, std::to_string(flows) + " boundaries' mean flows differ");
      check(same_bits(a.inlet_mean_flow, b.inlet_mean_flow) && same_bits(a.outlets_mean_flow, b.outlets_mean_flow),
            "the in- and outflow differ");
      check(same_bits(a.volume_change, b.volume_change), "the volume change differs");
      check(same_bits(a.conservation_error, b.conservation_error) && a.inflow_measured == b.inflow_measured,
            "the mass balance differs: " + std::to_string(a.conservation_error) + " and " + std::to_string(b.conservation_error));
      check(a.volume_change != 0 && a.inlet_mean_flow > 0, "nothing moved");
    } else {
      // Every other rank holds its own vessels' results alone, by entry: its 0D system's
      // vessels in their order, then its 1D vessels (64 B an own vessel, not a network's).
      const LumpedVessels& lumped = mine.lumped();
      const std::size_t entries = lumped.vessel_count() + mine.one_d_vessels().size();
      check(b.vessels.size() == entries && entries < net.vessel_count(),
            "rank " + std::to_string(rank) + " holds " + std::to_string(b.vessels.size()) + " vessels' results, not its " +
                std::to_string(entries) + " entries");
      std::size_t differ = 0, own = 0;
      for (std::size_t e = 0; e < entries && e < b.vessels.size(); ++e) {
        const std::size_t v = e < lumped.vessel_count() ? lumped.network_vessel(e)
                                                        : static_cast<std::size_t>(mine.one_d_vessels()[e - lumped.vessel_count()]);
        if (!mine.steps_vessel(v)) continue;  // a ghost's entry: not its own
        ++own;
        differ += !same_bits(a.vessels[v].mean_pressure, b.vessels[e].mean_pressure) + !same_bits(a.vessels[v].peak_flow, b.vessels[e].peak_flow);
      }
      check(differ == 0 && own > 0, "rank " + std::to_string(rank) + ": " + std::to_string(differ) + " of its " +
                                        std::to_string(own) + " own vessels' results differ from the whole run's");
    }
  }
  const int failures = rank_checks::all_failures();
  if (rank == 0 && failures == 0) std::printf("cycle statistics over %d ranks: the whole run's bits\n", ranks);
  MPI_Finalize();
  return failures == 0 ? 0 : 1;
}
