// Rows of numbers gathered on rank 0 in the whole network's order, in one MPI_Gatherv: each
// rank sends `width` numbers per item of its own list (vessels, nodes, probes), in that
// list's order, and rank 0, which knows every rank's list, puts each row in its item's place.
// What a distributed run hands rank 0 to write its results as the one-process run does.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace hemotree {

// rows: this rank's, width per item of its list. lists: on rank 0, every rank's items (rank
// after rank; ignored elsewhere). count: the items of the whole. Rank 0 hands each row to
// place(item, row), rank after rank (row: `width` numbers, valid during the call), so that it
// holds the gathered rows once, not twice, and in rounds of at most about 64 MB of every
// rank's rows, never all of them at once. Collective over MPI_COMM_WORLD; SettingError
// "ranks" on every rank alike where count x width exceeds MPI's int counts.
void gather_rows(std::span<const double> rows, std::size_t width, const std::vector<std::vector<std::int32_t>>& lists,
                 std::size_t count, const std::function<void(std::int32_t item, const double* row)>& place);

// The same where rank 0 does not know the ranks' lists: each rank's `items` (its list) are
// gathered first (one MPI_Gatherv more).
void gather_rows(std::span<const std::int32_t> items, std::span<const double> rows, std::size_t width,
                 std::size_t count, const std::function<void(std::int32_t item, const double* row)>& place);

// One number an item: each rank's values at their places (place[i] >= 0: value i's item in the
// whole, of count items) written into rank 0's `into` (count long there; it may be `values`
// itself: they are read first), rank after rank; an item no rank places is left as it is.
// Collective; count alike on every rank.
void gather_places(std::span<const double> values, std::span<const std::int32_t> place, std::size_t count,
                   std::span<double> into);

// The same into a vector made here: on rank 0 every item's value (0 where no rank places
// one), empty elsewhere. Collective.
std::vector<double> gather_places(std::span<const double> values, std::span<const std::int32_t> place, std::size_t count);

// Every rank's list of items on rank 0, rank after rank (empty elsewhere): what rank 0 needs to
// place their rows or send them values. Collective.
std::vector<std::vector<std::int32_t>> gather_lists(std::span<const std::int32_t> items);

// The other way: rank 0's value of each item (whole: per item of the whole, on rank 0) sent to
// every rank for the items of its list (lists: every rank's, on rank 0), in its list's order;
// mine: this rank's list's length. Collective over MPI_COMM_WORLD.
std::vector<double> scatter_values(std::span<const double> whole, const std::vector<std::vector<std::int32_t>>& lists,
                                   std::size_t mine);

}  // namespace hemotree
