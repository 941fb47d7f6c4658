#include "distributed/steady_hematocrit_over_ranks.hpp"

#include <mpi.h>

#include <vector>

#include "distributed/gather_rows.hpp"
#include "distributed/steady_on_slices.hpp"
#include "distributed/steady_over_ranks.hpp"
#include "mpi/session.hpp"

namespace hemotree {

namespace {

// The one-process iteration's passes over the ranks. solve(): a pass's flows over the ranks
// with each rank's hematocrits (the whole flow on rank 0); send(h): rank 0's relaxed
// hematocrits h (per vessel of the network) to every rank, for its next solve. net, blood:
// rank 0's (the hematocrits are distributed on it).
template <class Solve, class Send>
SteadyHematocritOverRanks iterate(const Network& net, const Blood& blood, int max_iterations, double tolerance,
                                  double relaxation, Solve solve, Send send) {
  const bool lead = world_rank() == 0;
  std::vector<double> h(lead ? net.vessel_count() : 0, blood.hematocrit);  // rank 0's
  std::vector<double> previous_flow;                                       // rank 0's
  SteadyHematocritOverRanks out;
  SteadyHematocritResult& result = out.result;
  for (int it = 1; it <= max_iterations; ++it) {
    SteadyOverRanks solved = solve();
    out.partition = std::move(solved.partition);
    // Rank 0 holds the whole flow: the pass as the one-process iteration takes it, its refusal
    // (a hematocrit the law cannot give) every rank's.
    on_lead_rank([&] {
      HematocritPass pass = hematocrit_pass(net, blood, solved.flow, h, previous_flow);
      result.change = pass.change;
      result.converged = pass.change < tolerance;
      previous_flow = solved.flow.flow;
      result.flow = std::move(solved.flow);
      result.hematocrit = std::move(pass.target);
      if (!result.converged)
        for (std::size_t v = 0; v < h.size(); ++v) h[v] += relaxation * (result.hematocrit[v] - h[v]);
    });
    result.iterations = it;
    double decided[2] = {result.change, result.converged ? 1.0 : 0.0};
    MPI_Bcast(decided, 2, MPI_DOUBLE, 0, MPI_COMM_WORLD);
    result.change = decided[0];
    result.converged = decided[1] != 0;
    if (result.converged) break;
    send(h);
  }
  if (!lead) {
    result.flow = SteadyFlow{};
    result.hematocrit.clear();
  }
  return out;
}

}  // namespace

SteadyHematocritOverRanks solve_steady_with_phase_separation_over_ranks(const Network& net, const Blood& blood,
                                                                        int max_iterations, double tolerance,
                                                                        double relaxation) {
  on_every_rank([&] { check_phase_separation_settings(max_iterations, tolerance, relaxation); });
  SteadyFlowOverRanks flow(net, blood, net.inlet ? net.inlet->waveform.mean_value() : 0.0);  // set up once
  std::vector<double> mine(net.vessel_count(), blood.hematocrit);  // every rank's: its resistances
  return iterate(
      net, blood, max_iterations, tolerance, relaxation, [&] { return flow.solve(mine); },
      [&](const std::vector<double>& h) {
        if (world_rank() == 0) mine = h;
        MPI_Bcast(mine.data(), static_cast<int>(mine.size()), MPI_DOUBLE, 0, MPI_COMM_WORLD);
      });
}

std::optional<SteadyHematocritOverRanks> solve_steady_with_phase_separation_on_slices(
    const Network& held, const std::string& path, const std::function<Blood(const Network&)>& blood_of,
    int max_iterations, double tolerance, double relaxation) {
  on_every_rank([&] { check_phase_separation_settings(max_iterations, tolerance, relaxation); });
  SteadyFlowOnSlices slices(held, path, blood_of);
  if (!slices.serves()) return std::nullopt;
  const Blood blood = blood_of(held);
  // Each rank's hematocrits for its slice's vessels alone: rank 0 sends each its own.
  const std::vector<std::vector<std::int32_t>> lists = gather_lists(slices.vessels());
  std::vector<double> mine(slices.vessels().size(), blood.hematocrit);
  return iterate(
      held, blood, max_iterations, tolerance, relaxation, [&] { return slices.solve(mine); },
      [&](const std::vector<double>& h) { mine = scatter_values(h, lists, mine.size()); });
}

}  // namespace hemotree
