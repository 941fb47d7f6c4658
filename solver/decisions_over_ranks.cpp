#include "solver/decisions_over_ranks.hpp"

#include <algorithm>
#include <cstdint>

#include <mpi.h>

#include "mpi/session.hpp"
#include "pulse/solution_breakdown.hpp"

namespace hemotree {

int interrupt_on_any_rank(int signal) {
  int largest = signal;
  MPI_Allreduce(&signal, &largest, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  return largest;
}

double largest_on_ranks(double value) {
  double largest = value;
  MPI_Allreduce(&value, &largest, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  return largest;
}

void take_lead_values(std::vector<double>& values) {
  auto count = static_cast<std::uint64_t>(values.size());
  MPI_Bcast(&count, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
  values.resize(static_cast<std::size_t>(count));
  // In pieces below 2^31 numbers, MPI's count.
  constexpr std::size_t piece = std::size_t{1} << 30;
  for (std::size_t at = 0; at < values.size(); at += piece)
    MPI_Bcast(values.data() + at, static_cast<int>(std::min(piece, values.size() - at)), MPI_DOUBLE, 0, MPI_COMM_WORLD);
}

void take_lead_text(std::string& text) {
  auto count = static_cast<std::uint64_t>(text.size());
  MPI_Bcast(&count, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
  text.resize(static_cast<std::size_t>(count));
  constexpr std::size_t piece = std::size_t{1} << 30;
  for (std::size_t at = 0; at < text.size(); at += piece)
    MPI_Bcast(text.data() + at, static_cast<int>(std::min(piece, text.size() - at)), MPI_CHAR, 0, MPI_COMM_WORLD);
}

PeriodicityChange lead_change(PeriodicityChange change) {
  auto vessel = static_cast<std::uint64_t>(change.vessel);
  MPI_Bcast(&change.change, 1, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  MPI_Bcast(&vessel, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
  change.vessel = static_cast<std::size_t>(vessel);
  return change;
}

void check_solution_on_every_rank(const PulseSolver& solver) {
  const int none = world_size();
  int failed = none;
  std::int64_t vessel = 0;
  double at = 0;
  try {
    solver.check_solution();
  } catch (const SolutionBreakdown& e) {
    failed = world_rank();
    vessel = e.vessel;
    at = e.at;
  }
  int first = failed;
  MPI_Allreduce(&failed, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (first == none) return;
  MPI_Bcast(&vessel, 1, MPI_INT64_T, first, MPI_COMM_WORLD);
  MPI_Bcast(&at, 1, MPI_DOUBLE, first, MPI_COMM_WORLD);
  throw SolutionBreakdown(vessel, at);
}

}  // namespace hemotree
