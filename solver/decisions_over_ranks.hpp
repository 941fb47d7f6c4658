// What the ranks of a pulsatile run over ranks decide together (docs/scaling.md, "The
// pulsatile run over ranks"): each rank meets its own interrupts, clock and failures, and the
// whole cycle's results pass through rank 0 alone; every decision the time loop takes on them (stop,
// go on, balance, break down) must be every rank's at the same step, or a rank would be left
// waiting in the next exchange. Each call is collective over MPI_COMM_WORLD: every rank makes
// it at the same point of the run.
#pragma once

#include <exception>
#include <string>
#include <vector>

#include "pulse/pulse_solver.hpp"
#include "solver/cycle_statistics.hpp"

namespace hemotree {

// The largest signal any rank was asked to stop by (0: none): an interrupt on one rank stops
// every rank.
int interrupt_on_any_rank(int signal);
// The largest over the ranks: the slowest rank's seconds.
double largest_on_ranks(double value);
// Rank 0's values (any length) on every rank: what rank 0 alone computes from the whole
// cycle's results (the compliance balance's moves, the red cells' change).
void take_lead_values(std::vector<double>& values);
// Rank 0's text (any length: a checkpoint's bytes) on every rank.
void take_lead_text(std::string& text);
// Rank 0's cycle-to-cycle change (of the whole cycle's results, which it alone sees) on every rank.
PeriodicityChange lead_change(PeriodicityChange change);
// PulseSolver::check_solution on every rank's vessels: where any fails, SolutionBreakdown on
// every rank, the lowest failing rank's (its first vessel in the network's order).
void check_solution_on_every_rank(const PulseSolver& solver);
// Where any rank's failure (null: none) is a SolutionBreakdown, throws the lowest such rank's
// on every rank, as the solver says it alone (a breakdown a step's messages refused carries
// words only); else returns. Every rank calls it after the same refusal.
void breakdown_on_every_rank(std::exception_ptr failure);

}  // namespace hemotree
