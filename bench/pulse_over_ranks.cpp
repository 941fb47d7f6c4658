// The pulsatile solver's steps over MPI ranks (issue 24; pulse/pulse_solver.hpp's PulseRanks):
// a tree's 0D vessels cut into whole subtrees, its 1D vessels and every vessel above them on
// the top's rank, one gather and one scatter a 0D step. Run under mpirun; rank 0 prints the
// set-up's and the steps' seconds, the exchanges of rank 0 and of the top's rank (collective
// calls, bytes, seconds inside them, waiting for the slowest rank included), each rank's peak
// resident memory, a fingerprint of every vessel's flow and pressure at its centre after the
// last step, in the vessels' order, and one of the steps' statistics as a run takes them (500
// samples, gathered on rank 0 at the close): the same for any number of ranks where the bits are.
//
// usage: mpirun -np P build/bench/pulse_over_ranks NETWORK [STEPS] [THREADS]
//        NETWORK a tree fed into outlets (vgen | vprune's); STEPS default (or 0): one cycle;
//        THREADS a rank, default 1. The models --model auto chooses, one pi section a 0D
//        vessel (--lumped-sections 1), the steady start.
#include <sys/resource.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include <mpi.h>

#include "formats/network_io.hpp"
#include "mpi/session.hpp"
#include "pulse/pulse_solver.hpp"
#include "solver/cycle_over_ranks.hpp"
#include "solver/cycle_statistics.hpp"
#include "solver/pulse_ranks_mpi.hpp"

using namespace hemotree;

namespace {

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

int main(int argc, char** argv) {
  MpiSession session(argc, argv);
  if (argc < 2 || argc > 4) {
    if (world_rank() == 0) std::fprintf(stderr, "usage: mpirun -np P pulse_over_ranks NETWORK [STEPS] [THREADS]\n");
    return 2;
  }
  const int ranks = world_size(), rank = world_rank();
  const auto started = std::chrono::steady_clock::now();
  const Network net = read_network(argv[1]);
  SolverOptions options;
  options.model = ModelChoice::automatic;
  options.lumped_sections = 1;
  options.start = StartChoice::steady;
  options.threads = argc > 3 ? std::atoi(argv[3]) : 1;

  MpiPulseRanks over_ranks(net, std::vector<double>(net.vessel_count(), 1.0));
  const PulseRanks& part = over_ranks.ranks();
  PulseSolver solver(net, options, &part);
  MPI_Barrier(MPI_COMM_WORLD);
  const double set_up = seconds_since(started);
  std::size_t one_d = 0;
  for (std::size_t v = 0; v < net.vessel_count(); ++v) one_d += solver.is_lumped(v) ? 0 : 1;
  const std::size_t top_vessels = over_ranks.top_vessels();
  const long asked = argc > 2 ? std::atol(argv[2]) : 0;
  const std::size_t steps = asked > 0 ? static_cast<std::size_t>(asked)
                                      : static_cast<std::size_t>(std::llround(solver.period() / solver.dt()));
  // The cycle's statistics as a run samples them (solver/pulsatile_run.cpp: 500 samples a
  // cycle with 0D vessels), gathered on rank 0 at the close.
  CycleStatistics stats(net, solver, 1 / solver.period());
  const auto stats_every = std::max<std::size_t>(1, static_cast<std::size_t>(static_cast<double>(steps) / 500));
  const auto stepping = std::chrono::steady_clock::now();
  stats.begin(solver);
  double sampled_until = solver.time();
  for (std::size_t k = 0; k < steps; ++k) {
    solver.step();
    if ((k + 1) % stats_every == 0 || k + 1 == steps) {
      stats.sample(solver, solver.time(), solver.time() - sampled_until);
      sampled_until = solver.time();
    }
  }
  CycleSummary cycle = stats.close(solver);
  if (solver.over_ranks()) gather_cycle_vessels(net, solver, cycle, stats.entry_vessels(solver));  // rank 0's: every vessel's
  MPI_Barrier(MPI_COMM_WORLD);
  const double stepped = seconds_since(stepping);
  const RootExchange* exchange = over_ranks.exchange();  // made at the first step

  // Each vessel's centre flow and pressure from the rank that steps it, in the vessels' order.
  std::vector<double> mine;
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    if (solver.steps_vessel(v)) mine.insert(mine.end(), {static_cast<double>(v), solver.flow_at(v, 0.5), solver.pressure_at(v, 0.5)});
  }
  int count = static_cast<int>(mine.size());
  std::vector<int> counts(static_cast<std::size_t>(ranks)), offsets(counts.size(), 0);
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  for (std::size_t r = 1; r < counts.size(); ++r) offsets[r] = offsets[r - 1] + counts[r - 1];
  std::vector<double> all(rank == 0 ? static_cast<std::size_t>(offsets.back() + counts.back()) : 0);
  MPI_Gatherv(mine.data(), count, MPI_DOUBLE, all.data(), counts.data(), offsets.data(), MPI_DOUBLE, 0, MPI_COMM_WORLD);
  struct rusage usage {};
  getrusage(RUSAGE_SELF, &usage);
  long peak_kb = usage.ru_maxrss;
  std::vector<long> peaks(static_cast<std::size_t>(ranks));
  MPI_Gather(&peak_kb, 1, MPI_LONG, peaks.data(), 1, MPI_LONG, 0, MPI_COMM_WORLD);
  // The top's exchanges too.
  double top_traffic[3] = {0, 0, 0};
  if (rank == part.top_rank && exchange)
    top_traffic[0] = exchange->traffic().calls, top_traffic[1] = static_cast<double>(exchange->traffic().bytes),
    top_traffic[2] = exchange->traffic().seconds;
  if (part.top_rank != 0) {
    if (rank == part.top_rank) MPI_Send(top_traffic, 3, MPI_DOUBLE, 0, 7, MPI_COMM_WORLD);
    if (rank == 0) MPI_Recv(top_traffic, 3, MPI_DOUBLE, part.top_rank, 7, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  }
  if (rank == 0) {
    std::vector<double> flow(net.vessel_count(), 0.0), pressure(net.vessel_count(), 0.0);
    std::vector<unsigned char> seen(net.vessel_count(), 0);
    for (std::size_t k = 0; k < all.size(); k += 3) {
      const auto v = static_cast<std::size_t>(all[k]);
      flow[v] = all[k + 1];
      pressure[v] = all[k + 2];
      ++seen[v];
    }
    std::size_t missing = 0;
    for (const unsigned char s : seen) missing += s != 1;
    std::uint64_t hash = 1469598103934665603ull;  // FNV-1a over the numbers' bits
    for (std::size_t v = 0; v < flow.size(); ++v)
      for (const double x : {flow[v], pressure[v]}) {
        std::uint64_t bits = std::bit_cast<std::uint64_t>(x);
        for (int b = 0; b < 8; ++b, bits >>= 8) hash = (hash ^ (bits & 0xff)) * 1099511628211ull;
      }
    std::printf("%d ranks x %d threads, %zu vessels (%zu 1D, %zu on the top's rank %d), %zu steps of %d substeps:\n"
                "  set-up %.2f s, steps %.2f s (%.1f ms a step)\n",
                ranks, options.threads, net.vessel_count(), one_d, top_vessels, part.top_rank, steps, solver.substeps(),
                set_up, stepped, 1e3 * stepped / static_cast<double>(steps));
    if (exchange)
      std::printf("  rank 0's exchanges: %d calls, %zu B, %.3f s inside; the top's: %.0f calls, %.0f B, %.3f s\n",
                  exchange->traffic().calls, exchange->traffic().bytes, exchange->traffic().seconds, top_traffic[0],
                  top_traffic[1], top_traffic[2]);
    std::printf("  peak resident memory a rank:");
    for (const long kb : peaks) std::printf(" %.0f MiB", static_cast<double>(kb) / 1024);
    std::printf("\n  fingerprint of the vessels' centre flows and pressures: %016llx%s\n",
                static_cast<unsigned long long>(hash), missing ? " (vessels missing or twice!)" : "");
    std::uint64_t cycle_hash = 1469598103934665603ull;  // the statistics: every vessel's, then the totals
    auto add = [&](double x) {
      std::uint64_t bits = std::bit_cast<std::uint64_t>(x);
      for (int b = 0; b < 8; ++b, bits >>= 8) cycle_hash = (cycle_hash ^ (bits & 0xff)) * 1099511628211ull;
    };
    for (const VesselCycle& c : cycle.vessels)
      for (const double x : {c.mean_flow, c.mean_pressure, c.systolic_pressure, c.diastolic_pressure, c.peak_flow,
                             c.least_flow, c.mean_wss, c.reynolds})
        add(x);
    for (const auto& [v, w] : cycle.waves) add(w.pressure), add(w.velocity);
    for (const double x : {cycle.inlet_mean_flow, cycle.outlets_mean_flow, cycle.volume_change, cycle.conservation_error}) add(x);
    std::printf("  the cycle's statistics: in %.6g ml/min, mass balance %.3g; fingerprint %016llx\n",
                cycle.inlet_mean_flow * 6e7, cycle.conservation_error, static_cast<unsigned long long>(cycle_hash));
  }
  return 0;
}
