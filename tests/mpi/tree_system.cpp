// Under mpirun (ctest label mpi, 1 to 4 ranks): a grown tree's nodal system solved over the
// ranks (distributed/mpi_tree_system.hpp) gives on every rank the whole system's potentials
// bit for bit, a second solve with the same factorisation too, and each share root's parent
// potential; numbers one rank refuses are thrown on every rank (that rank's own message
// there); a forest with no path to ground is said singular on every rank. Exit 0 when every
// rank agrees, 1 otherwise, one line per failure on stderr.
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>

#include <mpi.h>

#include "distributed/mpi_tree_system.hpp"
#include "distributed/network_cut.hpp"
#include "../grown_trees.hpp"
#include "network_flow/nodal_system.hpp"
#include "partition/partition.hpp"
#include "rank_checks.hpp"

using namespace hemotree;
using rank_checks::check;
using rank_checks::rank;

int main(int argc, char** argv) {
  const int ranks = rank_checks::start(&argc, &argv);
  {
    const Network net = test_networks::grown_tree();
    const std::size_t nodes = net.node_count(), edges = net.vessel_count();
    // The same numbers on every rank: conductances over four decades, shunts at the leaves.
    std::mt19937_64 random(11);
    std::uniform_real_distribution<double> unit(0, 1);
    std::vector<double> g(edges), shunt(nodes), b(nodes), b2(nodes);
    std::vector<int> degree(nodes, 0);
    for (std::size_t e = 0; e < edges; ++e) ++degree[static_cast<std::size_t>(net.from[e])], ++degree[static_cast<std::size_t>(net.to[e])];
    for (double& x : g) x = std::pow(10.0, -12 + 4 * unit(random));
    for (std::size_t i = 0; i < nodes; ++i) {
      shunt[i] = degree[i] == 1 ? std::pow(10.0, -11 + 2 * unit(random)) : 0.0;
      b[i] = unit(random) - 0.5;
      b2[i] = unit(random);
    }
    NodalSystem whole(nodes, net.from, net.to);
    whole.factorize(g, shunt);
    std::vector<double> x(nodes), x2(nodes);
    whole.solve(b, x);
    whole.solve(b2, x2);

    const Partition partition = partition_network(net, std::vector<double>(edges, 1.0), ranks);
    const TreeCut cut = tree_cut(net, partition);
    MpiTreeSystem system(MPI_COMM_WORLD, cut);
    const auto mine = system.nodes();
    std::vector<double> my_g, my_shunt, my_x, my_x2;
    for (const std::int32_t node : mine) {
      const std::int32_t e = cut.parent_edge[static_cast<std::size_t>(node)];
      my_g.push_back(e >= 0 ? g[static_cast<std::size_t>(e)] : 0.0);
      my_shunt.push_back(shunt[static_cast<std::size_t>(node)]);
      my_x.push_back(b[static_cast<std::size_t>(node)]);
      my_x2.push_back(b2[static_cast<std::size_t>(node)]);
    }
    check(system.factorize_solve(my_g, my_shunt, my_x) == -1, "singular where the whole is not");
    system.solve(my_x2);
    std::size_t differ = 0, differ2 = 0;
    for (std::size_t k = 0; k < mine.size(); ++k) {
      const auto node = static_cast<std::size_t>(mine[k]);
      differ += std::bit_cast<std::uint64_t>(my_x[k]) != std::bit_cast<std::uint64_t>(x[node]);
      differ2 += std::bit_cast<std::uint64_t>(my_x2[k]) != std::bit_cast<std::uint64_t>(x2[node]);
    }
    check(differ == 0, std::to_string(differ) + " of " + std::to_string(mine.size()) + " potentials not the whole's bits");
    check(differ2 == 0, std::to_string(differ2) + " potentials of the second solve not the whole's bits");
    for (std::size_t k = 0; k < system.root_parents().size(); ++k) {
      const std::int32_t p = system.root_parents()[k];
      check(p >= 0 && std::bit_cast<std::uint64_t>(system.root_parent_potentials()[k]) ==
                          std::bit_cast<std::uint64_t>(x2[static_cast<std::size_t>(p)]),
            "a root's parent potential");
    }
    std::size_t held = 0, all = 0;
    held = mine.size();
    MPI_Allreduce(&held, &all, 1, MPI_UNSIGNED_LONG, MPI_SUM, MPI_COMM_WORLD);
    check(all == nodes, "the ranks hold " + std::to_string(all) + " nodes of " + std::to_string(nodes));

    // The last rank refuses a conductance (of its first node's edge, into the top): every
    // rank throws that rank's words.
    std::vector<double> bad_g = my_g;
    if (rank == ranks - 1 && !bad_g.empty()) bad_g.front() = -1;
    try {
      system.factorize_solve(bad_g, my_shunt, my_x);
      check(false, "a negative conductance solved");
    } catch (const std::invalid_argument& e) {
      const std::string said = e.what();
      const std::string from = ranks > 1 ? "rank " + std::to_string(ranks - 1) + ": " : "";
      check(said.find("the distributed solve: " + from + "TreeShare::factorize_forward: the conductance of node") == 0,
            "refusal said as: " + said);
    }
    // No shunt anywhere: singular, the same node on every rank.
    std::vector<double> no_shunt(mine.size(), 0.0);
    const std::int64_t singular = system.factorize_solve(my_g, no_shunt, my_x);
    std::int64_t lowest = singular, highest = singular;
    MPI_Allreduce(&singular, &lowest, 1, MPI_INT64_T, MPI_MIN, MPI_COMM_WORLD);
    MPI_Allreduce(&singular, &highest, 1, MPI_INT64_T, MPI_MAX, MPI_COMM_WORLD);
    check(singular >= 0 && lowest == highest, "singular said as " + std::to_string(singular));
    // A solve after that factorisation: refused on every rank alike, no rank left waiting.
    try {
      system.solve(my_x2);
      check(false, "a solve after a singular factorisation");
    } catch (const std::logic_error& e) {
      check(std::string(e.what()).find("no factorisation succeeded on every rank") != std::string::npos,
            std::string("refused as: ") + e.what());
    }
  }
  const int total = rank_checks::all_failures();
  if (rank == 0 && total == 0) std::printf("%d ranks: the whole system's bits\n", ranks);
  MPI_Finalize();
  return total == 0 ? 0 : 1;
}
