// Under mpirun (ctest label mpi, 1 to 4 ranks): the pulsatile solver's steps with the 1D
// vessels spread over the ranks (pulse/one_d_cut.hpp, docs/scaling.md item 11). The tree with
// waves (83 vessels 1D above subtrees of 0D vessels): each 0D subtree on one rank, the 1D
// vessels wherever the partition puts them, so that junctions and 1D ends coupled to 0D nodes
// lie across the cut (over 3 and 4 ranks); after every step, and after two compliance balances, each rank's own
// vessels are the one-process solver's bits; its checkpoint over the ranks is the one-process
// bytes, and every rank restored from that steps on to its bits. Then a small tree all 1D.
// Exit 0 when every rank agrees, 1 otherwise, one line per failure on stderr.
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

std::size_t differing(const Network& net, const PulseSolver& mine, const PulseSolver& whole) {
  std::size_t differ = 0;
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    if (!mine.steps_vessel(v)) continue;
    for (const double x : {0.0, 0.3, 0.5, 1.0})
      differ += !same_bits(mine.pressure_at(v, x), whole.pressure_at(v, x)) + !same_bits(mine.flow_at(v, x), whole.flow_at(v, x));
  }
  return differ;
}

// Steps both solvers `steps` times, the compliance balance at the given steps; the numbers of
// this rank's vessels that differ, and how many vessels it holds.
std::size_t step_both(const Network& net, PulseSolver& whole, PulseSolver& mine, int steps, std::vector<int> balances) {
  std::size_t differ = 0;
  for (int n = 0; n < steps; ++n) {
    for (const int b : balances)
      if (n == b) {
        const std::size_t a = whole.balance_compliances(whole.period()), c = mine.balance_compliances(mine.period());
        check(a == c, "the balance moved " + std::to_string(c) + " vessels, the whole run's " + std::to_string(a));
      }
    whole.step();
    mine.step();
    differ += differing(net, mine, whole);
  }
  return differ;
}

void check_every_vessel_held(const Network& net, const PulseSolver& mine) {
  unsigned long held = 0, total = 0;
  for (std::size_t v = 0; v < net.vessel_count(); ++v) held += mine.steps_vessel(v) ? 1 : 0;
  MPI_Allreduce(&held, &total, 1, MPI_UNSIGNED_LONG, MPI_SUM, MPI_COMM_WORLD);
  check(total == net.vessel_count(), std::to_string(total) + " vessels held over the ranks, of " + std::to_string(net.vessel_count()));
}

}  // namespace

int main(int argc, char** argv) {
  const int ranks = rank_checks::start(&argc, &argv);
  {
    const Network net = test_networks::tree_with_waves();
    const SolverOptions options = test_networks::options_over_ranks();
    PulseSolver whole(net, options);
    MpiPulseRanks over_ranks(net, std::vector<double>(net.vessel_count(), 1.0), OneDLayout::spread);
    PulseSolver mine(net, options, &over_ranks.ranks());
    check(mine.one_d_spread() == (ranks > 1), "the 1D vessels not spread over " + std::to_string(ranks) + " ranks");
    check(mine.dt() == whole.dt() && mine.substeps() == whole.substeps() && mine.coupling_passes() == whole.coupling_passes(),
          "another step than the whole run's");
    check_every_vessel_held(net, mine);
    // Coupled ends across the cut on some rank, where there is a cut.
    int crossing = 0, any = 0;
    std::vector<std::int32_t> lumped_at(net.node_count(), -1);  // a 0D vessel at each node
    for (std::size_t v = 0; v < net.vessel_count(); ++v)
      if (mine.is_lumped(v)) lumped_at[static_cast<std::size_t>(net.from[v])] = lumped_at[static_cast<std::size_t>(net.to[v])] = static_cast<std::int32_t>(v);
    for (const auto& c : mine.network_boundaries().coupled) {
      const auto zero_d = static_cast<std::size_t>(lumped_at[static_cast<std::size_t>(c.node)]);
      crossing += mine.steps_vessel(static_cast<std::size_t>(c.end.vessel)) && !mine.steps_vessel(zero_d) ? 1 : 0;
    }
    MPI_Allreduce(&crossing, &any, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
    // (Over 2 ranks this partition keeps every coupled node with its ends; over 3 and 4 it does not.)
    if (ranks > 2) check(any > 0, "no 1D end coupled to another rank's 0D node");
    const std::size_t differ = step_both(net, whole, mine, 20, {5, 15});
    check(differ == 0, std::to_string(differ) + " numbers differ from the whole run's");
    check(mine.time() == whole.time(), "another time than the whole run's");

    CheckpointWriter one;
    whole.save(one);
    std::optional<CheckpointWriter> written;
    if (rank == 0) written.emplace();
    mine.save_over_ranks(written ? &*written : nullptr);
    if (rank == 0)
      check(written->bytes() == one.bytes(), "the checkpoint over ranks (" + std::to_string(written->bytes().size()) +
                                                 " bytes) is not the one-process one's (" + std::to_string(one.bytes().size()) + ")");
    PulseSolver resumed(net, options, &over_ranks.ranks());
    CheckpointReader in(one.bytes(), "the one-process checkpoint");
    resumed.restore(in);
    check(in.at_end(), "bytes left after the restore");
    const std::size_t after = step_both(net, whole, resumed, 10, {});
    check(after == 0, std::to_string(after) + " numbers differ from the one-process run's after the restore");
    if (rank == 0) std::printf("the tree with waves, 1D spread: %d ends coupled across the cut\n", any);
  }
  {
    // A small tree all 1D: a top would leave the other ranks without a vessel.
    const Network net = test_networks::tree_with_waves(250e-6);
    SolverOptions options = test_networks::options_over_ranks();
    options.model = ModelChoice::one_d;
    PulseSolver whole(net, options);
    MpiPulseRanks over_ranks(net, std::vector<double>(net.vessel_count(), 1.0));
    PulseSolver mine(net, options, &over_ranks.ranks());
    check(mine.one_d_spread() == (ranks > 1), "an all-1D tree not spread over " + std::to_string(ranks) + " ranks");
    check_every_vessel_held(net, mine);
    const std::size_t differ = step_both(net, whole, mine, 20, {10});
    check(differ == 0, std::to_string(differ) + " numbers differ from the whole run's (all 1D)");
    if (rank == 0) std::printf("a tree of %zu vessels all 1D, %zu steps\n", net.vessel_count(), mine.steps());
  }
  const int failures = rank_checks::all_failures();
  if (rank == 0 && failures == 0) std::printf("pulsatile steps with the 1D vessels spread over %d ranks: the whole run's bits\n", ranks);
  MPI_Finalize();
  return failures == 0 ? 0 : 1;
}
