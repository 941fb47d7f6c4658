// Under mpirun (ctest label mpi, 1 to 4 ranks): a grown tree's harmonic system (complex
// two-ports, not symmetric) solved over the ranks (distributed/mpi_harmonic_tree.hpp) gives
// on every rank the whole system's potentials bit for bit, and each share root's parent
// potential (and on the top's rank every share root's); a zero pivot, on the top or inside a
// share, is refused on every rank alike. Exit 0 when every rank agrees, 1
// otherwise, one line per failure on stderr.
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <stdexcept>
#include <string>

#include <mpi.h>

#include "distributed/mpi_harmonic_tree.hpp"
#include "distributed/network_cut.hpp"
#include "../grown_trees.hpp"
#include "network_flow/harmonic_system.hpp"
#include "partition/partition.hpp"
#include "rank_checks.hpp"

using namespace hemotree;
using rank_checks::check;
using rank_checks::rank;

namespace {

bool same_bits(Complex a, Complex b) {
  return std::bit_cast<std::uint64_t>(a.real()) == std::bit_cast<std::uint64_t>(b.real()) &&
         std::bit_cast<std::uint64_t>(a.imag()) == std::bit_cast<std::uint64_t>(b.imag());
}

}  // namespace

int main(int argc, char** argv) {
  const int ranks = rank_checks::start(&argc, &argv);
  {
    const Network net = test_networks::grown_tree();
    const std::size_t nodes = net.node_count(), edges = net.vessel_count();
    // The same numbers on every rank: lines with a mean flow through them, outlets at the leaves.
    std::mt19937_64 random(13);
    std::uniform_real_distribution<double> unit(0, 1);
    std::vector<TwoPort> y(edges);
    std::vector<Complex> shunt(nodes), current(nodes);
    std::vector<int> degree(nodes, 0);
    for (std::size_t e = 0; e < edges; ++e) ++degree[static_cast<std::size_t>(net.from[e])], ++degree[static_cast<std::size_t>(net.to[e])];
    for (TwoPort& t : y) {
      const Complex g(std::pow(10.0, -12 + 4 * unit(random)), 1e-13 * unit(random)), c(0, 1e-14 * unit(random));
      const double flow = 0.2 * (unit(random) - 0.5);
      t = {g + c, -g * (1.0 + flow), -g * (1.0 - flow), g + c * (1 + flow)};
    }
    for (std::size_t i = 0; i < nodes; ++i) {
      shunt[i] = degree[i] == 1 ? Complex(std::pow(10.0, -11 + 2 * unit(random)), 1e-12 * unit(random)) : Complex(0.0);
      current[i] = Complex(unit(random) - 0.5, unit(random) - 0.5);
    }
    const std::vector<Complex> x = HarmonicSystem(nodes, net.from, net.to).solve(y, shunt, current);

    const Partition partition = partition_network(net, std::vector<double>(edges, 1.0), ranks);
    const TreeCut cut = tree_cut(net, partition);
    MpiHarmonicTree system(MPI_COMM_WORLD, cut);
    const auto mine = system.nodes();
    std::vector<Complex> my_shunt, my_x;
    std::vector<EdgeToParent> my_edge;
    for (const std::int32_t node : mine) {
      const std::int32_t e = cut.parent_edge[static_cast<std::size_t>(node)];
      my_edge.push_back(e >= 0 ? EdgeToParent::of(y[static_cast<std::size_t>(e)], net.from[static_cast<std::size_t>(e)] == node)
                               : EdgeToParent{});
      my_shunt.push_back(shunt[static_cast<std::size_t>(node)]);
      my_x.push_back(current[static_cast<std::size_t>(node)]);
    }
    system.solve(my_shunt, my_edge, my_x);
    std::size_t differ = 0;
    for (std::size_t k = 0; k < mine.size(); ++k) differ += !same_bits(my_x[k], x[static_cast<std::size_t>(mine[k])]);
    check(differ == 0, std::to_string(differ) + " of " + std::to_string(mine.size()) + " potentials not the whole's bits");
    for (std::size_t k = 0; k < system.root_parents().size(); ++k)
      check(same_bits(system.root_parent_potentials()[k], x[static_cast<std::size_t>(system.root_parents()[k])]),
            "a root's parent potential");
    for (std::size_t k = 0; k < system.share_roots().size(); ++k)
      check(same_bits(system.share_root_potentials()[k], x[static_cast<std::size_t>(system.share_roots()[k])]),
            "a share root's potential on the top's rank");
    std::size_t held = mine.size(), all = 0;
    MPI_Allreduce(&held, &all, 1, MPI_UNSIGNED_LONG, MPI_SUM, MPI_COMM_WORLD);
    check(all == nodes, "the ranks hold " + std::to_string(all) + " nodes of " + std::to_string(nodes));
    if (ranks > 1) {
      MPI_Allreduce(MPI_IN_PLACE, &differ, 1, MPI_UNSIGNED_LONG, MPI_SUM, MPI_COMM_WORLD);
      std::size_t roots = system.root_parents().size();
      MPI_Allreduce(MPI_IN_PLACE, &roots, 1, MPI_UNSIGNED_LONG, MPI_SUM, MPI_COMM_WORLD);
      check(roots >= static_cast<std::size_t>(ranks) - 1, "a cut with " + std::to_string(roots) + " share roots");
    }

    // No shunt anywhere and pure series edges: a zero pivot, refused on every rank alike.
    std::vector<Complex> no_shunt(mine.size(), 0.0);
    std::vector<EdgeToParent> series(my_edge.size());
    for (std::size_t k = 0; k < series.size(); ++k) series[k] = EdgeToParent::of(TwoPort::series(Complex(1.0, 0.5)), true);
    try {
      system.solve(no_shunt, series, my_x);
      check(false, "a forest with no admittance to ground solved");
    } catch (const std::invalid_argument& e) {
      check(std::string(e.what()).find("no admittance to ground") != std::string::npos, std::string("refused as: ") + e.what());
    }
    // A zero pivot inside the last rank's share (its last node, a leaf: its diagonal its shunt
    // and its edge's term), refused on every rank alike.
    {
      std::vector<Complex> zero_leaf = my_shunt;
      const std::size_t share_nodes = cut.share_nodes(rank).size();
      if (rank == ranks - 1 && share_nodes > 0) zero_leaf[share_nodes - 1] = -my_edge[share_nodes - 1].own;
      try {
        system.solve(zero_leaf, my_edge, my_x);
        check(false, "a zero pivot in a share solved");
      } catch (const std::invalid_argument& e) {
        check(std::string(e.what()).find("no admittance to ground") != std::string::npos, std::string("refused as: ") + e.what());
      }
    }
    // Numbers of the wrong count on the last rank: its words on every rank.
    try {
      system.solve(my_shunt, my_edge, rank == ranks - 1 ? std::span<Complex>(my_x).first(0) : std::span<Complex>(my_x));
      check(false, "a short array solved");
    } catch (const std::invalid_argument& e) {
      const std::string from = ranks > 1 ? "rank " + std::to_string(ranks - 1) + ": " : "";
      check(std::string(e.what()).find("the distributed harmonic solve: " + from + "MpiHarmonicTree:") == 0,
            std::string("refused as: ") + e.what());
    }
  }
  const int total = rank_checks::all_failures();
  if (rank == 0 && total == 0) std::printf("%d ranks: the whole harmonic system's bits\n", ranks);
  MPI_Finalize();
  return total == 0 ? 0 : 1;
}
