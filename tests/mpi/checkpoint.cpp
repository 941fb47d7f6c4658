// Under mpirun (ctest label mpi, 1 to 4 ranks): a checkpoint of the pulsatile solver over ranks
// (PulseSolver::save_over_ranks) is the one-process solver's, byte for byte: rank 0, the top's,
// writes its 1D state with every rank's share of the 0D vessels and boundaries at the whole
// run's places (pulse/lumped_order.hpp's lumped_places). The wave tree with every third outlet
// an RCR (a capacitor node and an R1 edge at a 0D vessel's end), after a compliance balance.
// Then every rank restores its share from the one-process checkpoint and steps on: each rank's
// vessels are the one-process solver's bits after it. Exit 0 when every rank agrees.
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include <mpi.h>

#include "formats/checkpoint_file.hpp"
#include "pulse/pulse_solver.hpp"
#include "rank_checks.hpp"
#include "tree_with_waves.hpp"
#include "solver/pulse_ranks_mpi.hpp"

using namespace hemotree;
using rank_checks::check;
using rank_checks::rank;

using test_networks::same_bits;

namespace {

// Every third outlet an RCR of the same resistance: 30 % proximal, a capacitance giving a
// time constant of a tenth of the period.
Network with_rcr_outlets(Network net) {
  for (std::size_t k = 0; k < net.outlets.size(); k += 3) {
    Outlet& o = net.outlets[k];
    const double r = o.resistance();
    o.type = BoundaryType::rcr;
    o.r1 = 0.3 * r;
    o.r2 = 0.7 * r;
    o.c = 0.1 / o.r2;
  }
  return net;
}

std::size_t differing(const Network& net, const PulseSolver& mine, const PulseSolver& whole) {
  std::size_t differ = 0;
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    if (!mine.steps_vessel(v)) continue;
    for (const double x : {0.0, 0.5, 1.0})
      differ += !same_bits(mine.pressure_at(v, x), whole.pressure_at(v, x)) + !same_bits(mine.flow_at(v, x), whole.flow_at(v, x));
  }
  if (mine.holds_one_d()) differ += (mine.state().area != whole.state().area) + (mine.state().flow != whole.state().flow);
  return differ;
}

}  // namespace

int main(int argc, char** argv) {
  const int ranks = rank_checks::start(&argc, &argv);
  {
    const Network net = with_rcr_outlets(test_networks::tree_with_waves());
    const SolverOptions options = test_networks::options_over_ranks();
    PulseSolver whole(net, options);
    MpiPulseRanks over_ranks(net, std::vector<double>(net.vessel_count(), 1.0));
    PulseSolver mine(net, options, &over_ranks.ranks());
    check(over_ranks.ranks().top_rank == 0, "the top on rank " + std::to_string(over_ranks.ranks().top_rank) + ", not 0");
    for (int n = 0; n < 20; ++n) {
      if (n == 5 || n == 15) {
        whole.balance_compliances(whole.period());
        mine.balance_compliances(mine.period());
      }
      whole.step();
      mine.step();
    }
    CheckpointWriter one;
    whole.save(one);

    std::optional<CheckpointWriter> written;
    if (rank == 0) written.emplace();
    mine.save_over_ranks(written ? &*written : nullptr);
    if (rank == 0) {

      check(written->bytes() == one.bytes(), "the checkpoint over ranks (" + std::to_string(written->bytes().size()) +
                                                 " bytes) is not the one-process one's (" + std::to_string(one.bytes().size()) + ")");
      check(one.bytes().size() > 100000, "a checkpoint of " + std::to_string(one.bytes().size()) + " bytes");
    }
    // Each rank's share from the one-process checkpoint, then ten more steps with both.
    PulseSolver resumed(net, options, &over_ranks.ranks());
    CheckpointReader in(one.bytes(), "the one-process checkpoint");
    resumed.restore(in);
    check(in.at_end(), "bytes left after the restore");
    for (int n = 0; n < 10; ++n) {
      whole.step();
      resumed.step();
    }
    const std::size_t differ = differing(net, resumed, whole);
    check(differ == 0, std::to_string(differ) + " numbers differ from the one-process run's after the restore");
    check(resumed.time() == whole.time(), "another time after the restore");
  }
  const int failures = rank_checks::all_failures();
  if (rank == 0 && failures == 0) std::printf("checkpoints over %d ranks: the one-process bytes, resumed to its bits\n", ranks);
  MPI_Finalize();
  return failures == 0 ? 0 : 1;
}
