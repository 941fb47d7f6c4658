// Under mpirun (ctest label mpi, 1 to 4 ranks): a grown tree's 0D vessels cut over the ranks
// (pulse/lumped_cut.hpp), each step's messages carried by MPI (solver/lumped_link_mpi.hpp):
// after every step each rank's nodes, vessels and capacitors hold the bits of the whole run
// (which every rank also steps here, alone), with one thread a rank or two, and a coupling
// node's prediction and impedance on the top's rank; a step abandoned on the top's rank is
// refused on every rank with its words. Exit 0 when every rank agrees, 1 otherwise, one line
// per failure on stderr.
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include <mpi.h>

#include "../grown_trees.hpp"
#include "distributed/root_exchange.hpp"
#include "mpi/session.hpp"
#include "partition/partition.hpp"
#include "physics/viscosity_table.hpp"
#include "pulse/lumped_cut.hpp"
#include "pulse/lumped_vessels.hpp"
#include "rank_checks.hpp"
#include "solver/lumped_link_mpi.hpp"
#include "steady/vessel_laws.hpp"

using namespace hemotree;
using rank_checks::check;
using rank_checks::rank;

namespace {

bool same(double a, double b) { return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b); }

}  // namespace

int main(int argc, char** argv) {
  const int ranks = rank_checks::start(&argc, &argv);
  {
    const Network net = test_networks::fed_tree(BoundaryType::rcr, Waveform::constant_value(1e-9 / 60));
    const Blood blood = net.blood.value_or(Blood{});
    const std::vector<TubeLaw> laws = vessel_laws(net, blood, 0.0, 0.1);
    const ViscosityTable viscosity{blood};
    const std::vector<bool> all(net.vessel_count(), true);
    const LumpedOrder whole_order = subtree_lumped_order(net, all);
    const Partition p = partition_network(net, std::vector<double>(net.vessel_count(), 1.0), ranks);
    std::vector<std::int32_t> vessel_rank(p.rank_of_vessel.begin(), p.rank_of_vessel.end());
    for (const std::int32_t v : p.top) vessel_rank[static_cast<std::size_t>(v)] = p.top_rank;
    const int top = p.top_rank;
    const bool is_top = rank == top;
    const LumpedCut cut = lumped_cut(net, whole_order, vessel_rank, ranks, top, rank);
    const std::int32_t coupled = net.to[0];  // a coupling node on the top's rank
    check(vessel_rank[0] == top, "the root vessel is not on the top's rank");
    std::vector<double> pressure(net.node_count()), flow(net.vessel_count(), 0.0);
    for (std::size_t i = 0; i < pressure.size(); ++i) pressure[i] = 4000.0 - 1.3 * static_cast<double>(i % 997);
    const double dt = 2e-4;

    for (const int threads : {1, 2}) {
      LumpedVessels whole(net, laws, viscosity, blood, all);
      whole.start(pressure, flow);
      whole.set_coupling_nodes({whole.node_of(coupled)});
      LumpedVessels mine(net, laws, viscosity, blood, all, {}, {}, {}, &cut);
      RootExchange exchange(MPI_COMM_WORLD, top, cut.roots);
      mine.set_link(mpi_lumped_link(exchange));
      mine.set_threads(threads);
      mine.start(pressure, flow);
      if (is_top) mine.set_coupling_nodes({mine.node_of(coupled)});
      std::size_t differ = 0, compared = 0;
      for (int n = 0; n < 40; ++n) {
        const double time = dt * (n + 1);
        const double inlet = 1e-10 * (1 + 0.5 * std::sin(2 * M_PI * time / 0.01));
        const double coupled_in = 2e-11 * (1 + std::cos(2 * M_PI * time / 0.013)), coupled_volume = 0.97 * dt * coupled_in;
        whole.predict(dt, std::vector<double>{coupled_in}, std::vector<double>{inlet}, {});
        mine.predict(dt, is_top ? std::vector<double>{coupled_in} : std::vector<double>{},
                     std::vector<double>(mine.inflow_boundaries().size(), inlet), {});
        if (is_top)
          differ += !same(mine.pressure_during_step(0, 1.0), whole.pressure_during_step(0, 1.0)) +
                    !same(mine.impedance(0), whole.impedance(0));
        whole.complete(std::vector<double>{coupled_volume});
        mine.complete(is_top ? std::vector<double>{coupled_volume} : std::vector<double>{});
        compared = 0;
        for (std::size_t node = 0; node < net.node_count(); ++node) {
          const std::int32_t k = mine.node_of(static_cast<std::int64_t>(node));
          if (k < 0 || mine.ghost_node(k)) continue;
          ++compared;
          differ += !same(mine.node_pressure(k), whole.node_pressure(whole.node_of(static_cast<std::int64_t>(node))));
        }
        for (std::size_t v = 0; v < net.vessel_count(); ++v) {
          const std::int32_t i = mine.vessel_index(v);
          if (i < 0 || mine.ghost_vessel(i)) continue;
          ++compared;
          differ += !same(mine.flow(i), whole.flow(whole.vessel_index(v)));
        }
        for (std::size_t o = 0; o < net.outlets.size(); ++o)
          if (vessel_rank[static_cast<std::size_t>(net.outlets[o].vessel)] == rank) {
            ++compared;
            differ += !same(mine.capacitor_pressure(o), whole.capacitor_pressure(o));
          }
      }
      check(differ == 0, std::to_string(differ) + " numbers differ from the whole run's, threads " + std::to_string(threads));
      // Every node, vessel and capacitor held by exactly one rank.
      unsigned long held = compared, total = 0;
      MPI_Allreduce(&held, &total, 1, MPI_UNSIGNED_LONG, MPI_SUM, MPI_COMM_WORLD);
      check(total == net.node_count() + net.vessel_count() + net.outlets.size(),
            std::to_string(total) + " numbers held over the ranks");
      check(exchange.traffic().calls == 120, std::to_string(exchange.traffic().calls) + " collective calls for 40 steps (the roots up, the potentials and the pressures down)");
    }

    // The top's rank abandons a step between its halves: every rank refuses it, in its words.
    LumpedVessels mine(net, laws, viscosity, blood, all, {}, {}, {}, &cut);
    RootExchange exchange(MPI_COMM_WORLD, top, cut.roots);
    mine.set_link(mpi_lumped_link(exchange));
    mine.start(pressure, flow);
    std::string words;
    try {
      mine.predict(dt, {}, std::vector<double>(mine.inflow_boundaries().size(), 1e-10), {});
      if (is_top) mine.abandon_step(std::make_exception_ptr(std::runtime_error("the 1D vessels failed")));
      mine.complete({});
    } catch (const std::invalid_argument& e) {
      words = e.what();
    }
    check(words.find("the 0D step") != std::string::npos && words.find("the 1D vessels failed") != std::string::npos,
          "the abandoned step refused as \"" + words + "\"");
  }
  const int failures = rank_checks::all_failures();
  if (rank == 0 && failures == 0) std::printf("lumped step over %d ranks: the whole run's bits\n", ranks);
  MPI_Finalize();
  return failures == 0 ? 0 : 1;
}
