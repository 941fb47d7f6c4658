// The distended steady state over MPI ranks (issue 24): what a pulsatile run over ranks will
// start from, and the shape of its 0D step (one distributed factorisation and solve a sweep).
// Run under mpirun; rank 0 prints one line: the ranks, the sweeps, the seconds of the
// iteration (set-up excluded), and its own share of the exchanges (collective calls, bytes,
// seconds inside them, waiting for the slowest rank included).
//
// usage: mpirun -np P build/bench/distended_over_ranks NETWORK   (a tree fed into outlets, its
//        labels from its inlet: vgen | vprune's)
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <mpi.h>

#include "distributed/distended_over_ranks.hpp"
#include "distributed/network_cut.hpp"
#include "formats/network_io.hpp"
#include "mpi/session.hpp"
#include "partition/partition.hpp"
#include "physics/viscosity_table.hpp"
#include "steady/vessel_laws.hpp"

using namespace hemotree;

int main(int argc, char** argv) {
  MpiSession session(argc, argv);
  if (argc != 2) {
    if (world_rank() == 0) std::fprintf(stderr, "usage: mpirun -np P distended_over_ranks NETWORK\n");
    return 2;
  }
  const Network net = read_network(argv[1]);
  const Blood blood = net.blood.value_or(Blood{});
  const std::vector<TubeLaw> laws = vessel_laws(net, blood, 0.0, 0.1);
  const ViscosityTable viscosity(blood);
  const Partition partition = partition_network(net, std::vector<double>(net.vessel_count(), 1.0), world_size());
  const TreeCut cut = tree_cut(net, partition);
  MPI_Barrier(MPI_COMM_WORLD);
  const auto started = std::chrono::steady_clock::now();
  const DistendedOverRanks mine = solve_distended_steady_flow_over_ranks(
      net, cut, blood, laws, viscosity, net.inlet ? net.inlet->waveform.mean_value() : 0.0);
  MPI_Barrier(MPI_COMM_WORLD);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  if (world_rank() == 0)
    std::printf("%d ranks, %zu vessels: %d sweeps in %.3f s; rank 0's exchanges: %d collective calls, %zu bytes, %.4f s\n",
                world_size(), net.vessel_count(), mine.sweeps, seconds, mine.traffic.calls, mine.traffic.bytes,
                mine.traffic.seconds);
  return 0;
}
