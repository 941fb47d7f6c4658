// Under mpirun (ctest label mpi, 1 to 4 ranks): the pulsatile solver's steps over the ranks
// (pulse/pulse_solver.hpp's PulseRanks): a grown tree whose larger vessels are 1D, kept with
// every vessel above them on the top's rank, and whose 0D vessels are cut into whole subtrees;
// after every step, and after two compliance balances, each rank's 0D vessels and, on the
// top's rank, the 1D vessels' whole state are the one-process solver's bits (which every rank
// also steps here, alone); so is every rank's periodic start, the lead's sent. Exit 0 when
// every rank agrees, 1 otherwise, one line per failure on stderr.
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include <mpi.h>

#include "pulse/pulse_solver.hpp"
#include "rank_checks.hpp"
#include "tree_with_waves.hpp"
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
    std::size_t one_d = 0;
    for (std::size_t v = 0; v < net.vessel_count(); ++v) one_d += whole.is_lumped(v) ? 0 : 1;
    check(one_d > 10 && one_d < net.vessel_count() / 4,
          std::to_string(one_d) + " of " + std::to_string(net.vessel_count()) + " vessels 1D");

    // The partition by subtrees, the 1D vessels and those above them on the top's rank.
    MpiPulseRanks over_ranks(net, std::vector<double>(net.vessel_count(), 1.0));
    const PulseRanks& part = over_ranks.ranks();
    PulseSolver mine(net, options, &part);
    check(mine.holds_one_d() == (rank == part.top_rank), "the 1D vessels held by a rank not the top's");
    check(mine.dt() == whole.dt() && mine.substeps() == whole.substeps() && mine.coupling_passes() == whole.coupling_passes(),
          "another step than the whole run's");
    std::size_t differ = 0, compared = 0;
    // The compliance balance at "cycle ends" (steps 10 and 20: the first marks the volumes, the
    // second moves every compliance) over ranks too: its inputs made whole on every rank.
    std::size_t moved = 0;
    for (int n = 0; n < 30; ++n) {
      if (n == 10 || n == 20) {
        const std::size_t a = whole.balance_compliances(whole.period()), b = mine.balance_compliances(mine.period());
        check(a == b, "the balance moved " + std::to_string(b) + " vessels, the whole run's " + std::to_string(a));
        moved += a;
      }
      whole.step();
      mine.step();
      compared = 0;
      for (std::size_t v = 0; v < net.vessel_count(); ++v) {
        if (!mine.steps_vessel(v)) continue;
        ++compared;
        for (const double x : {0.0, 0.5, 1.0})
          differ += !same_bits(mine.pressure_at(v, x), whole.pressure_at(v, x)) + !same_bits(mine.flow_at(v, x), whole.flow_at(v, x));
      }
      if (mine.holds_one_d()) {
        differ += mine.state().area != whole.state().area;
        differ += mine.state().flow != whole.state().flow;
      }
    }
    check(differ == 0, std::to_string(differ) + " numbers differ from the whole run's");
    unsigned long held = compared, total = 0;
    MPI_Allreduce(&held, &total, 1, MPI_UNSIGNED_LONG, MPI_SUM, MPI_COMM_WORLD);
    check(total == net.vessel_count(), std::to_string(total) + " vessels held over the ranks, of " + std::to_string(net.vessel_count()));
    check(mine.time() == whole.time(), "another time than the whole run's");
    check(moved == net.vessel_count(), "the balance moved " + std::to_string(moved) + " vessels");
    if (rank == 0) std::printf("%zu vessels (%zu 1D), %zu steps of %d substeps\n", net.vessel_count(), one_d, mine.steps(), mine.substeps());
  }
  {
    // The periodic start, which the lead alone solves and sends (PulseSolver::take_lead_start):
    // every rank's vessels, and the 1D state, the one-process start's bits, and then a step.
    const Network net = test_networks::tree_with_waves();
    SolverOptions options = test_networks::options_over_ranks();
    options.start = StartChoice::periodic;
    PulseSolver whole(net, options);
    MpiPulseRanks over_ranks(net, std::vector<double>(net.vessel_count(), 1.0));
    PulseSolver mine(net, options, &over_ranks.ranks());
    check(whole.started_from() == StartChoice::periodic && mine.started_from() == StartChoice::periodic,
          "not started from the periodic state");
    std::size_t differ = 0;
    for (int n = 0; n < 2; ++n) {
      for (std::size_t v = 0; v < net.vessel_count(); ++v) {
        if (!mine.steps_vessel(v)) continue;
        for (const double x : {0.0, 0.5, 1.0})
          differ += !same_bits(mine.pressure_at(v, x), whole.pressure_at(v, x)) + !same_bits(mine.flow_at(v, x), whole.flow_at(v, x));
      }
      if (n == 0 || mine.holds_one_d()) {  // at the start every rank holds every 1D vessel's rows
        differ += mine.state().area != whole.state().area;
        differ += mine.state().flow != whole.state().flow;
      }
      whole.step();
      mine.step();
    }
    check(differ == 0, std::to_string(differ) + " numbers of the periodic start differ from the whole run's");
  }
  const int failures = rank_checks::all_failures();
  if (rank == 0 && failures == 0) std::printf("pulsatile steps over %d ranks: the whole run's bits\n", ranks);
  MPI_Finalize();
  return failures == 0 ? 0 : 1;
}
