// Node ids to node indices: how a reader resolves the ids a file names nodes by (vessels'
// ends, boundaries) once the nodes are read, and finds an id given twice (of nodes, or of
// vessels: any list of ids). Shared by the JSON and the HDF5 reader.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

namespace hemotree {

struct NodeIndex {
  std::vector<std::pair<std::int64_t, std::int32_t>> sorted;  // (id, index) by id
  bool identity = true;  // ids 0..n-1 in order, the usual case: no search needed

  explicit NodeIndex(const std::vector<std::int64_t>& ids) {
    for (std::size_t i = 0; i < ids.size(); ++i)
      if (ids[i] != static_cast<std::int64_t>(i)) identity = false;
    if (identity) return;
    sorted.reserve(ids.size());
    for (std::size_t i = 0; i < ids.size(); ++i)
      sorted.emplace_back(ids[i], static_cast<std::int32_t>(i));
    std::sort(sorted.begin(), sorted.end());
  }
  std::size_t size() const { return identity ? 0 : sorted.size(); }
  // The lowest id given twice and its first two places; none where every id is one's own.
  struct Repeat {
    std::int64_t id;
    std::int32_t first, second;
  };
  std::optional<Repeat> repeat() const {
    for (std::size_t i = 1; i < sorted.size(); ++i)
      if (sorted[i].first == sorted[i - 1].first) return Repeat{sorted[i].first, sorted[i - 1].second, sorted[i].second};
    return std::nullopt;
  }
  // -1 when unknown
  std::int32_t find(std::int64_t id, std::size_t count) const {
    if (identity) return id >= 0 && id < static_cast<std::int64_t>(count)
                             ? static_cast<std::int32_t>(id) : -1;
    auto it = std::lower_bound(sorted.begin(), sorted.end(), std::make_pair(id, std::int32_t{0}));
    return it != sorted.end() && it->first == id ? it->second : -1;
  }
};

}  // namespace hemotree
