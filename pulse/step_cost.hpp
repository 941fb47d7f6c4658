// What a step costs (measured on this project's machines, bench/README.md): the run's
// estimate (solver/run_estimate) and the choice of the 1D-0D coupling passes
// (pulse/pulse_time_stepping.cpp) both weigh the 1D vessels' substeps against the 0D step.
#pragma once

namespace hemotree::step_cost {

// The 5301-vessel network (2516, 2639 and 146 elements of degree 1, 2 and 7) takes 2.5 ms a
// step on one core of the Intel Xeon VM (0.77 ms on the AMD EPYC one); the carotid (one
// element of degree 7) 10 us, nearly all of it per-step overhead. The slower machine sets
// the constants: an estimate that errs should err long.
inline constexpr double per_step = 10e-6;       // [s per step]
inline constexpr double per_element = 300e-9;   // [s per element and step]
inline constexpr double per_mode_pair = 18e-9;  // [s per element, step and (p + 1)^2]
// 0D vessels: one linearisation, factorisation and two solves of the nodal system per step,
// and the cycle statistics' samples. Measured with two threads 42 ns a vessel and step on
// 1 M and 3.8 M vessels (bench/README.md, "The lean engine"), about 76 ns on one at two
// threads' 1.8-fold speed-up: 100 ns, so that the estimate errs long.
inline constexpr double per_lumped_vessel = 100e-9;  // [s per 0D vessel and step]

// A 0D system spread over ranks (pulse/lumped_halo.hpp): each step solves it over the ranks
// (PETSc), once and once more per coupling node, each solve a few collective calls and a few
// iterations over a rank's nodes. Measured (bench/README.md, "A 0D system with loops over
// ranks", 2 ranks): the mesentery's 565 nodes a rank 0.3 to 0.4 ms a solve, a mesh's 20,000
// nodes a rank 17 ms: 0.3 ms and 0.85 us a node, rounded up.
inline constexpr double per_spread_solve = 0.4e-3;   // [s per solve]
inline constexpr double per_spread_node = 1e-6;      // [s per node of a rank and solve]

// One step of one element of degree p, fitted to steps of one degree everywhere
// (bench/README.md, "Cost model"): a fixed part per element (traces, Riemann problems,
// friction) and a part that grows with the modes times the quadrature points of the degree's
// products.
constexpr double element_step_seconds(int degree) {
  const double modes = degree + 1;
  return per_element + per_mode_pair * modes * modes;
}

// Each coupling pass lengthens the 0D step by this fraction of the period, up to the most
// passes measured within issue 5's tolerances of --model 1d (docs/solver.md §10).
inline constexpr double step_per_coupling_pass = 1e-3;
inline constexpr int most_coupling_passes = 4;

// The 1D-0D coupling passes that cost least per cycle: the 1D substeps cost one_d per pass,
// the 0D steps zero_d at a thousandth of the period, fewer as each pass lengthens the step by
// another thousandth: N one_d + zero_d / N. One pass more pays while zero_d / (N (N + 1)) >
// one_d (least near N = sqrt(zero_d / one_d)); at most `most`.
constexpr int cheapest_coupling_passes(double one_d, double zero_d, int most) {
  int passes = 1;
  while (passes < most && zero_d / (passes * (passes + 1.0)) > one_d) ++passes;
  return passes;
}

}  // namespace hemotree::step_cost
