// Under mpirun (ctest label mpi, 1 to 4 ranks): a cycle's statistics over ranks
// (solver/cycle_over_ranks.hpp): each rank samples the vessels it steps; at the cycle's close
// rank 0 holds every vessel's results, the 1D vessels' wave speeds, every boundary's mean
// flow, the in- and outflow, the volume change and the mass balance with the bits of the
// one-process run's statistics (which every rank also takes here, alone); and the probes,
// each sampled by the rank that steps its vessel, give rank 0 the one-process probes.csv rows. Exit 0 when every
// rank agrees, 1 otherwise, one line per failure on stderr.
#include <bit>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include <mpi.h>

#include "generator/growth_rules.hpp"
#include "generator/tree_growth.hpp"
#include "pruner/outlet_calibration.hpp"
#include "pruner/pruning_strategies.hpp"
#include "pulse/pulse_solver.hpp"
#include "rank_checks.hpp"
#include "solver/cycle_statistics.hpp"
#include "solver/probes_over_ranks.hpp"
#include "solver/pulse_ranks_mpi.hpp"

using namespace hemotree;
using rank_checks::check;
using rank_checks::rank;

namespace {

bool same(double a, double b) { return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b); }

// As tests/mpi/pulse_step.cpp's: vgen --seed 3 --root-diameter 1mm --min-diameter 50um | vprune --budget all.
Network tree_with_waves() {
  GrowthParameters p;
  p.root_diameter = 1e-3;
  p.min_diameter = 50e-6;
  p.seed = 3;
  Network full = grow_tree(default_rules(), p);
  full.blood = Blood{};
  Inlet inlet;
  inlet.vessel = full.id[0];
  inlet.waveform.mean = 1.74e-6 / 60;
  full.inlet = inlet;
  const KeepMask keep(full.vessel_count(), 1);
  Network net = extract(full, keep);
  calibrate_outlets(full, keep, net, OutletParameters{});
  return net;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  {
    const Network net = tree_with_waves();
    SolverOptions options;
    options.model = ModelChoice::automatic;
    options.lumped_sections = 1;
    options.start = StartChoice::steady;
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
    const CycleSummary a = whole_stats.close(whole), b = stats.close(mine);
    if (rank == 0) {
      std::size_t differ = 0;
      check(b.vessels.size() == a.vessels.size(), "the vessels' results of " + std::to_string(b.vessels.size()) + " vessels");
      for (std::size_t v = 0; v < a.vessels.size() && v < b.vessels.size(); ++v) {
        const VesselCycle &x = a.vessels[v], &y = b.vessels[v];
        differ += !same(x.mean_flow, y.mean_flow) + !same(x.mean_pressure, y.mean_pressure) +
                  !same(x.systolic_pressure, y.systolic_pressure) + !same(x.diastolic_pressure, y.diastolic_pressure) +
                  !same(x.peak_flow, y.peak_flow) + !same(x.least_flow, y.least_flow) + !same(x.mean_wss, y.mean_wss) +
                  !same(x.reynolds, y.reynolds);
      }
      check(differ == 0, std::to_string(differ) + " vessel results differ from the whole run's");
      check(a.waves.size() == b.waves.size() && !a.waves.empty(), "the wave speeds of " + std::to_string(b.waves.size()) + " vessels");
      for (std::size_t k = 0; k < a.waves.size() && k < b.waves.size(); ++k)
        check(a.waves[k].first == b.waves[k].first && same(a.waves[k].second.pressure, b.waves[k].second.pressure) &&
                  same(a.waves[k].second.velocity, b.waves[k].second.velocity),
              "the wave speeds of vessel " + std::to_string(a.waves[k].first));
      check(a.boundary_mean_flow.size() == b.boundary_mean_flow.size(), "the boundaries' mean flows");
      std::size_t flows = 0;
      for (std::size_t k = 0; k < a.boundary_mean_flow.size() && k < b.boundary_mean_flow.size(); ++k)
        flows += !same(a.boundary_mean_flow[k], b.boundary_mean_flow[k]);
      check(flows == 0, std::to_string(flows) + " boundaries' mean flows differ");
      check(same(a.inlet_mean_flow, b.inlet_mean_flow) && same(a.outlets_mean_flow, b.outlets_mean_flow),
            "the in- and outflow differ");
      check(same(a.volume_change, b.volume_change), "the volume change differs");
      check(same(a.conservation_error, b.conservation_error) && a.inflow_measured == b.inflow_measured,
            "the mass balance differs: " + std::to_string(a.conservation_error) + " and " + std::to_string(b.conservation_error));
      check(a.volume_change != 0 && a.inlet_mean_flow > 0, "nothing moved");
    }
  }
  const int failures = rank_checks::all_failures();
  if (rank == 0 && failures == 0) std::printf("cycle statistics over %d ranks: the whole run's bits\n", ranks);
  MPI_Finalize();
  return failures == 0 ? 0 : 1;
}
