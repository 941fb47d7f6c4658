// A cycle's numbers over ranks (docs/scaling.md, "The pulsatile run over ranks", step 4): what
// every sum of a cycle needs, gathered on rank 0 item by item and summed there in the
// one-process order, so that rank 0 holds the one-process run's bits. Collective over
// MPI_COMM_WORLD: every rank calls each at the same point of the run.
#pragma once

#include <functional>
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

// Every vessel's cycle results on rank 0 from the rank that steps the vessel, a block of the
// vessels at a time in the network's order, without any rank holding them all: per vessel of
// the block [first, first + rows.size() / cycle_row_width) its row (cycle_row), handed to
// block(first, rows) on rank 0 alone. own: this rank's results (CycleStatistics::close),
// by entry where entry_vessel gives each entry's vessel (the ghosts' entries are not sent),
// else by vessel. block_vessels: the vessels a block (at most 5 MB of rows by default).
// Collective.
void gather_cycle_rows(const Network& net, const PulseSolver& solver, const CycleSummary& own,
                       std::span<const std::int32_t> entry_vessel,
                       const std::function<void(std::size_t first, std::span<const double> rows)>& block,
                       std::size_t block_vessels = std::size_t{1} << 16);

// The same into rank 0's `summary`, whole: every vessel's results by vessel and every 1D
// vessel's wave speeds. Elsewhere the summary is left as it is. Collective.
void gather_cycle_vessels(const Network& net, const PulseSolver& solver, CycleSummary& summary,
                          std::span<const std::int32_t> entry_vessel = {});

// Every vessel's mean pressure of the cycle on rank 0 (what the compliance balance takes),
// empty elsewhere. Collective.
std::vector<double> gather_mean_pressures(const Network& net, const PulseSolver& solver, const CycleSummary& own,
                                          std::span<const std::int32_t> entry_vessel);

}  // namespace hemotree
