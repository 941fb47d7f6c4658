// Under mpirun (ctest label mpi, 1 to 4 ranks): the distended steady state of a grown tree
// (inflow at its root, resistance outlets at its leaves) over the ranks
// (distributed/distended_over_ranks.hpp) gives each rank its share of the one-process
// solve_distended_steady_flow bit for bit: its nodes' pressures, its vessels' flows and
// resistances. Exit 0 when every rank agrees.
#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include <mpi.h>

#include "distributed/distended_over_ranks.hpp"
#include "distributed/network_cut.hpp"
#include "../grown_trees.hpp"
#include "mpi/session.hpp"
#include "partition/partition.hpp"
#include "steady/vessel_laws.hpp"

using namespace hemotree;

int main(int argc, char** argv) {
  int failures = 0;
  {
    MpiSession session(argc, argv);
    const int ranks = world_size(), rank = world_rank();
    // Every leaf an outlet of 2e13 Pa s/m^3 to 10 mmHg; 1 ul/min in at the root.
    const double inflow = 1e-9 / 60;
    const Network net = test_networks::fed_tree(BoundaryType::resistance, Waveform::constant_value(inflow));
    const Blood blood = net.blood.value_or(Blood{});
    const std::vector<TubeLaw> laws = vessel_laws(net, blood, 0.0, 0.1);
    const ViscosityTable viscosity(blood);
    std::vector<double> r_whole;
    const SteadyFlow whole = solve_distended_steady_flow(net, blood, laws, viscosity, inflow, &r_whole);

    const Partition partition = partition_network(net, std::vector<double>(net.vessel_count(), 1.0), ranks);
    const DistendedOverRanks mine =
        solve_distended_steady_flow_over_ranks(net, tree_cut(net, partition), blood, laws, viscosity, inflow);
    auto same = [](double a, double b) { return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b); };
    std::size_t differ = 0;
    for (const std::int32_t node : mine.nodes)
      differ += !same(mine.flow.node_pressure[static_cast<std::size_t>(node)], whole.node_pressure[static_cast<std::size_t>(node)]);
    for (const std::int32_t v : mine.vessels) {
      differ += !same(mine.flow.flow[static_cast<std::size_t>(v)], whole.flow[static_cast<std::size_t>(v)]);
      differ += !same(mine.resistance[static_cast<std::size_t>(v)], r_whole[static_cast<std::size_t>(v)]);
    }
    if (differ != 0 || mine.nodes.empty() || mine.sweeps < 3) {
      ++failures;
      std::fprintf(stderr, "rank %d: %zu numbers not the whole's bits (%zu nodes, %d sweeps)\n", rank, differ,
                   mine.nodes.size(), mine.sweeps);
    }
    // The inlet's pressure where this rank holds its node, as the whole's.
    const auto inlet = static_cast<std::size_t>(net.from[0]);
    if (std::binary_search(mine.nodes_by_label.begin(), mine.nodes_by_label.end(), static_cast<std::int32_t>(inlet)) &&
        !same(mine.flow.inlet_pressure, whole.inlet_pressure)) {
      ++failures;
      std::fprintf(stderr, "rank %d: the inlet's pressure not the whole's\n", rank);
    }
    std::size_t held = mine.nodes.size(), all = 0;
    MPI_Allreduce(&held, &all, 1, MPI_UNSIGNED_LONG, MPI_SUM, MPI_COMM_WORLD);
    if (all != net.node_count()) {
      ++failures;
      std::fprintf(stderr, "rank %d: the ranks hold %zu nodes of %zu\n", rank, all, net.node_count());
    }
    int total = 0;
    MPI_Allreduce(&failures, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
    failures = total;
    if (rank == 0 && total == 0)
      std::printf("%d ranks: the whole distended state's bits in %d sweeps\n", ranks, mine.sweeps);
  }
  return failures == 0 ? 0 : 1;
}
