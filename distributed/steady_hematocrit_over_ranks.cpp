#include "distributed/steady_hematocrit_over_ranks.hpp"

#include <mpi.h>

#include <vector>

#include "distributed/steady_over_ranks.hpp"
#include "mpi/session.hpp"

namespace hemotree {

SteadyHematocritOverRanks solve_steady_with_phase_separation_over_ranks(const Network& net, const Blood& blood,
                                                                        int max_iterations, double tolerance,
                                                                        double relaxation) {
  on_every_rank([&] { check_phase_separation_settings(max_iterations, tolerance, relaxation); });
  const double inlet_flow = net.inlet ? net.inlet->waveform.mean_value() : 0.0;
  const bool lead = world_rank() == 0;
  std::vector<double> h(net.vessel_count(), blood.hematocrit);  // every rank's: its resistances
  std::vector<double> previous_flow;                             // rank 0's
  SteadyHematocritOverRanks out;
  SteadyHematocritResult& result = out.result;
  SteadyFlowOverRanks flow(net, blood, inlet_flow);  // set up once, solved each pass
  for (int it = 1; it <= max_iterations; ++it) {
    SteadyOverRanks solved = flow.solve(h);
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
    MPI_Bcast(h.data(), static_cast<int>(h.size()), MPI_DOUBLE, 0, MPI_COMM_WORLD);
  }
  if (!lead) {
    result.flow = SteadyFlow{};
    result.hematocrit.clear();
  }
  return out;
}

}  // namespace hemotree
