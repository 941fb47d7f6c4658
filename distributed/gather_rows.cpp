#include "distributed/gather_rows.hpp"

#include <algorithm>
#include <limits>
#include <string>

#include <mpi.h>

#include "core/setting_error.hpp"
#include "mpi/session.hpp"

namespace hemotree {

void gather_rows(std::span<const double> rows, std::size_t width, const std::vector<std::vector<std::int32_t>>& lists,
                 std::size_t count, const std::function<void(std::int32_t item, const double* row)>& place) {
  if (count * width > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    throw Collective<SettingError>("ranks", placeholder("ranks") + ": " + std::to_string(count) + " rows of " +
                                                std::to_string(width) +
                                                " numbers are more than the gathering of the results on one rank takes yet");
  // In rounds of at most about 2^23 numbers (64 MB) on rank 0: each rank sends the same part of
  // its list in each round (the r-th of `rounds` equal parts), so that rank 0 never holds every
  // rank's rows at once. Every item is placed once, from its own row: the same results in any
  // number of rounds.
  constexpr std::size_t round_numbers = std::size_t{1} << 23;
  const std::size_t rounds = std::max<std::size_t>(1, (count * width + round_numbers - 1) / round_numbers);
  auto part = [rounds](std::size_t length, std::size_t r) { return length * r / rounds; };
  const bool lead = world_rank() == 0;
  const std::size_t mine = width > 0 ? rows.size() / width : 0;
  std::vector<double> all;
  for (std::size_t r = 0; r < rounds; ++r) {
    std::vector<int> counts, offsets;
    if (lead) {
      for (const auto& list : lists) {
        offsets.push_back(counts.empty() ? 0 : offsets.back() + counts.back());
        counts.push_back(static_cast<int>((part(list.size(), r + 1) - part(list.size(), r)) * width));
      }
    }
    all.resize(lead && !counts.empty() ? static_cast<std::size_t>(offsets.back() + counts.back()) : 0);
    const std::size_t first = part(mine, r), last = part(mine, r + 1);
    MPI_Gatherv(rows.data() + first * width, static_cast<int>((last - first) * width), MPI_DOUBLE, all.data(),
                counts.data(), offsets.data(), MPI_DOUBLE, 0, MPI_COMM_WORLD);
    if (!lead) continue;
    std::size_t from = 0;
    for (const auto& list : lists)
      for (std::size_t i = part(list.size(), r); i < part(list.size(), r + 1); ++i) {
        place(list[i], all.data() + from);
        from += width;
      }
  }
}

std::vector<std::vector<std::int32_t>> gather_lists(std::span<const std::int32_t> items) {
  const int ranks = world_size();
  const bool lead = world_rank() == 0;
  const int mine = static_cast<int>(items.size());
  std::vector<int> sizes(lead ? static_cast<std::size_t>(ranks) : 0), offsets(sizes.size(), 0);
  MPI_Gather(&mine, 1, MPI_INT, sizes.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  for (std::size_t r = 1; r < sizes.size(); ++r) offsets[r] = offsets[r - 1] + sizes[r - 1];
  std::vector<std::int32_t> every(lead ? static_cast<std::size_t>(offsets.back() + sizes.back()) : 0);
  MPI_Gatherv(items.data(), mine, MPI_INT32_T, every.data(), sizes.data(), offsets.data(), MPI_INT32_T, 0, MPI_COMM_WORLD);
  std::vector<std::vector<std::int32_t>> lists(sizes.size());
  for (std::size_t r = 0; r < sizes.size(); ++r)
    lists[r].assign(every.begin() + offsets[r], every.begin() + offsets[r] + sizes[r]);
  return lists;
}

void gather_rows(std::span<const std::int32_t> items, std::span<const double> rows, std::size_t width,
                 std::size_t count, const std::function<void(std::int32_t item, const double* row)>& place) {
  gather_rows(rows, width, gather_lists(items), count, place);
}

void gather_places(std::span<const double> values, std::span<const std::int32_t> place, std::size_t count,
                   std::span<double> into) {
  std::vector<std::int32_t> items;
  std::vector<double> rows;
  for (std::size_t i = 0; i < place.size(); ++i)
    if (place[i] >= 0) {
      items.push_back(place[i]);
      rows.push_back(values[i]);
    }
  gather_rows(items, rows, 1, count, [&](std::int32_t item, const double* row) { into[static_cast<std::size_t>(item)] = row[0]; });
}

std::vector<double> gather_places(std::span<const double> values, std::span<const std::int32_t> place, std::size_t count) {
  std::vector<double> whole(world_rank() == 0 ? count : 0, 0.0);
  gather_places(values, place, count, whole);
  return whole;
}

std::vector<double> scatter_values(std::span<const double> whole, const std::vector<std::vector<std::int32_t>>& lists,
                                   std::size_t mine) {
  const bool lead = world_rank() == 0;
  std::vector<int> counts, offsets;
  std::vector<double> packed;
  if (lead)
    for (const auto& list : lists) {
      offsets.push_back(static_cast<int>(packed.size()));
      counts.push_back(static_cast<int>(list.size()));
      for (const std::int32_t item : list) packed.push_back(whole[static_cast<std::size_t>(item)]);
    }
  std::vector<double> out(mine);
  MPI_Scatterv(packed.data(), counts.data(), offsets.data(), MPI_DOUBLE, out.data(), static_cast<int>(mine), MPI_DOUBLE, 0,
               MPI_COMM_WORLD);
  return out;
}

}  // namespace hemotree
