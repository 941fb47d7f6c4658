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

namespace {
// Rank 0's items (a vector's, a string's) on every rank, its length first; in pieces below
// 2^31 items, MPI's count.
template <class Items>
void take_lead_items(Items& items, MPI_Datatype type) {
  auto count = static_cast<std::uint64_t>(items.size());
  MPI_Bcast(&count, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
  items.resize(static_cast<std::size_t>(count));
  constexpr std::size_t piece = std::size_t{1} << 30;
  for (std::size_t at = 0; at < items.size(); at += piece)
    MPI_Bcast(items.data() + at, static_cast<int>(std::min(piece, items.size() - at)), type, 0, MPI_COMM_WORLD);
}
}  // namespace

void take_lead_values(std::vector<double>& values) { take_lead_items(values, MPI_DOUBLE); }

void take_lead_text(std::string& text) { take_lead_items(text, MPI_CHAR); }

PeriodicityChange lead_change(PeriodicityChange change) {
  auto vessel = static_cast<std::uint64_t>(change.vessel);
  MPI_Bcast(&change.change, 1, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  MPI_Bcast(&vessel, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
  change.vessel = static_cast<std::size_t>(vessel);
  return change;
}

void check_solution_on_every_rank(const PulseSolver& solver) {
  std::exception_ptr failure;
  try {
    solver.check_solution();
  } catch (const SolutionBreakdown&) {
    failure = std::current_exception();
  }
  breakdown_on_every_rank(failure);
}

void breakdown_on_every_rank(std::exception_ptr failure) {
  const int none = world_size();
  int failed = none;
  std::int64_t vessel = 0;
  double at = 0;
  if (failure) try {
      std::rethrow_exception(failure);
    } catch (const SolutionBreakdown& e) {
      failed = world_rank();
      vessel = e.vessel;
      at = e.at;
    } catch (...) {
    }
  int first = failed;
  MPI_Allreduce(&failed, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
  if (first == none) return;
  MPI_Bcast(&vessel, 1, MPI_INT64_T, first, MPI_COMM_WORLD);
  MPI_Bcast(&at, 1, MPI_DOUBLE, first, MPI_COMM_WORLD);
  throw SolutionBreakdown(vessel, at);
}

}  // namespace hemotree
