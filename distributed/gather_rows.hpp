// Rows of numbers gathered on rank 0 in the whole network's order, in one MPI_Gatherv: each
// rank sends `width` numbers per item of its own list (vessels, nodes, probes), in that
// list's order, and rank 0, which knows every rank's list, puts each row in its item's place.
// What a distributed run hands rank 0 to write its results as the one-process run does.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace hemotree {

// rows: this rank's, width per item of its list. lists: on rank 0, every rank's items (rank
// after rank; ignored elsewhere). count: the items of the whole. Returns, on rank 0, count x
// width numbers (an item no rank sent left NaN); empty elsewhere. Collective over
// MPI_COMM_WORLD; SettingError "ranks" on every rank alike where count x width exceeds MPI's
// int counts.
std::vector<double> gather_rows(std::span<const double> rows, std::size_t width,
                                const std::vector<std::vector<std::int32_t>>& lists, std::size_t count);

}  // namespace hemotree
