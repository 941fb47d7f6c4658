// Under mpirun (ctest label mpi, 1 to 4 ranks): rows gathered on rank 0 (distributed/
// gather_rows.hpp) in several rounds land each at its item's place, as one round puts them:
// 3 million items of width 3 (more than the 2^23 numbers of a round), dealt to the ranks
// unevenly and out of order, each row holding numbers of its item; rank 0's values of items
// scattered back (scatter_values) are each rank's own; numbers at places (gather_places) fill
// rank 0's array and leave an item no rank holds as it was. Exit 0 when every rank agrees.
#include <cstdint>
#include <string>
#include <vector>

#include <mpi.h>

#include "distributed/gather_rows.hpp"
#include "rank_checks.hpp"

using namespace hemotree;
using rank_checks::check;
using rank_checks::rank;

namespace {

double number(std::int32_t item, std::size_t j) { return 3.0 * item + 0.25 * static_cast<double>(j) + 1e-3; }

}  // namespace

int main(int argc, char** argv) {
  const int ranks = rank_checks::start(&argc, &argv);
  {
    constexpr std::size_t count = 3'000'000, width = 3;
    // Item i to rank (i * 7 + i / 1000) % P: uneven parts, each rank's list in decreasing order.
    std::vector<std::int32_t> mine;
    for (std::int64_t i = static_cast<std::int64_t>(count) - 1; i >= 0; --i)
      if ((i * 7 + i / 1000) % ranks == rank) mine.push_back(static_cast<std::int32_t>(i));
    std::vector<double> rows;
    for (const std::int32_t item : mine)
      for (std::size_t j = 0; j < width; ++j) rows.push_back(number(item, j));
    std::vector<double> whole(rank == 0 ? width * count : 0, -1.0);
    std::vector<int> placed(rank == 0 ? count : 0, 0);
    gather_rows(mine, rows, width, count, [&](std::int32_t item, const double* row) {
      ++placed[static_cast<std::size_t>(item)];
      for (std::size_t j = 0; j < width; ++j) whole[width * static_cast<std::size_t>(item) + j] = row[j];
    });
    if (rank == 0) {
      std::size_t wrong = 0, twice = 0;
      for (std::size_t i = 0; i < count; ++i) {
        twice += placed[i] != 1 ? 1 : 0;
        for (std::size_t j = 0; j < width; ++j)
          wrong += whole[width * i + j] != number(static_cast<std::int32_t>(i), j) ? 1 : 0;
      }
      check(twice == 0, std::to_string(twice) + " items not placed exactly once");
      check(wrong == 0, std::to_string(wrong) + " numbers not their item's");
    }

    // Back: rank 0's first number of each item to the rank whose list holds it.
    const std::vector<std::vector<std::int32_t>> lists = gather_lists(mine);
    std::vector<double> first(rank == 0 ? count : 0);
    for (std::size_t i = 0; i < first.size(); ++i) first[i] = whole[width * i];
    const std::vector<double> back = scatter_values(first, lists, mine.size());
    std::size_t wrong_back = 0;
    for (std::size_t k = 0; k < mine.size(); ++k) wrong_back += back[k] != number(mine[k], 0) ? 1 : 0;
    check(back.size() == mine.size() && wrong_back == 0, "scatter_values: " + std::to_string(wrong_back) + " wrong");

    // Numbers at places: every rank's items but item 5 (left as it was on rank 0).
    std::vector<std::int32_t> place(mine.size());
    std::vector<double> values(mine.size());
    for (std::size_t k = 0; k < mine.size(); ++k) {
      place[k] = mine[k] == 5 ? -1 : mine[k];
      values[k] = number(mine[k], 2);
    }
    std::vector<double> into(rank == 0 ? count : 0, -7.0);
    gather_places(values, place, count, into);
    if (rank == 0) {
      std::size_t wrong_places = 0;
      for (std::size_t i = 0; i < count; ++i)
        wrong_places += into[i] != (i == 5 ? -7.0 : number(static_cast<std::int32_t>(i), 2)) ? 1 : 0;
      check(wrong_places == 0, "gather_places: " + std::to_string(wrong_places) + " wrong");
    }
  }
  const int failures = rank_checks::all_failures();
  MPI_Finalize();
  return failures == 0 ? 0 : 1;
}
