// The settling cycle (docs/solver.md §6a): before a run that seeks the periodic state, one
// cycle of the whole network with the 0D step `settling_step` times as long as the run's,
// then the compliance balance at that cycle's mean pressures.
//
// From the linear periodic start the first cycle's mean lies about 1e-3 above the periodic
// one across the whole network (the 1D arteries' nonlinear mean shift, which the linear state
// lacks, drains through it); the balance after that cycle then lands within about 2e-5, so a
// run's first two cycles differ by the first's transient alone. The settling cycle takes that
// transient where the 0D vessels cost a third as much: its own mean differs from the run's
// step's by about 2e-4 (the 1D-0D coupling's error grows with the step), and the run's
// first two cycles then differ by less than 1e-3 (docs/solver.md §6a).
//
// Where the 1D vessels are the network (the large arteries), the first cycle's transient is
// their nonlinear pulse's, and the settling cycle is taken by a second solver of the same
// network and models with the 1D vessels at a low degree (a sixth of a cycle's cost), from
// whose state the run's solver then starts (PulseSolver::start_from; chosen by
// low_degree_settling_solver below, taken by solver/pulsatile_run.cpp).
#pragma once

#include <cstddef>
#include <memory>

#include "formats/network.hpp"
#include "pulse/pulse_solver.hpp"
#include "solver/run_configuration.hpp"
#include "solver/run_observer.hpp"

namespace hemotree {

struct Settling {
  std::size_t steps = 0;  // of the settling cycle (0: none taken)
  double seconds = 0;     // its wall time, the balance included
  int signal = 0;         // an interrupt request that stopped it (the state is then mid-cycle)
  int degree = 0;         // the 1D vessels' highest degree in it, where it took a lower one than the run's (else 0)
};

// One cycle of `steps` equal steps and the compliance balance after it; the solver's step and
// clock are then the run's again (its step as it was, t = 0). The balance is first called
// here at the cycle's start (it records the volumes the rates are taken from). Interrupt
// requests are polled every 256 steps; a breakdown throws SolutionBreakdown.
Settling settle(const Network& net, PulseSolver& solver, std::size_t steps, RunObserver& observer);

// The solver of the settling cycle at a lower 1D degree (RunConfiguration::settling_degree:
// the run's options with the 1D vessels' degrees capped and the step its own), or null where
// the run takes none: only where it seeks the periodic state from the steady network with the
// compliance balance and has 1D vessels above that degree. period: the pulse's [s]. ranks:
// the run's over MPI ranks, whose cut the second solver takes too (the same models, so the
// same partition: each rank starts its run's share from its settling share).
std::unique_ptr<PulseSolver> low_degree_settling_solver(const Network& net, const PulseSolver& run,
                                                       const RunConfiguration& config, double period,
                                                       const PulseRanks* ranks = nullptr);
// The steps of its cycle: its own stable step, taken in one coupling pass (a 0D step as long as
// the run's takes the run's passes' 1D substeps in one), and settling_step times longer where
// that is asked too (RunConfiguration::settling_step).
std::size_t low_degree_settling_steps(const PulseSolver& settling, double period, int settling_step);

}  // namespace hemotree
