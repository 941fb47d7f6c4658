// A cycle's numbers over ranks (docs/scaling.md, "The pulsatile run over ranks", step 4): what
// every sum of a cycle needs, gathered on rank 0 item by item and summed there in the
// one-process order, so that rank 0 holds the one-process run's bits. Collective over
// MPI_COMM_WORLD: every rank calls each at the same point of the run.
#pragma once

#include <span>
#include <vector>

#include <Eigen/Dense>

#include "formats/network.hpp"
#include "pulse/pulse_solver.hpp"
#include "solver/cycle_statistics.hpp"

namespace hemotree {

// PulseSolver::network_volume of the whole run on rank 0: each 0D node's stored volume from
// the rank that holds its row, in the 0D vessels' network order, then the top's 1D elements'
// volumes. Elsewhere NaN.
double network_volume_over_ranks(const Network& net, const PulseSolver& solver);

// PulseSolver::boundary_volumes of the whole run on rank 0 (each boundary from the rank that
// holds it); elsewhere empty.
Eigen::VectorXd boundary_volumes_over_ranks(const PulseSolver& solver);

// Per vessel, numbers each rank holds right for the vessels it steps (PulseSolver::sample_all's,
// a frame's), made every vessel's on rank 0 from the rank that steps it; elsewhere left.
void gather_vessel_values(const Network& net, const PulseSolver& solver, std::span<std::vector<double>* const> values);

// Every vessel's cycle results, and the wave speeds of the 1D vessels, from the rank that steps
// the vessel, into rank 0's `summary` (which holds this rank's own before the call, by vessel:
// the ghosts' and other ranks' entries are replaced). Elsewhere the summary is left as it is;
// its vessels' results are then each entry_vessel's where that is given (own-sized: the
// ghosts' entries are not sent), else by vessel.
void gather_cycle_vessels(const Network& net, const PulseSolver& solver, CycleSummary& summary,
                          std::span<const std::int32_t> entry_vessel = {});

}  // namespace hemotree
