#include "transport/transport_grid.hpp"

#include <algorithm>
#include <limits>
#include <string>

#include "core/errors.hpp"

namespace hemotree {

bool TransportGrid::faces_by_vessel() const {
  const std::int32_t most = vessel.empty() ? -1 : *std::max_element(vessel.begin(), vessel.end());
  std::vector<bool> seen(static_cast<std::size_t>(most + 1), false);
  for (std::size_t f = 0; f < vessel.size(); f = vessel_faces_end(f)) {
    if (vessel[f] < 0) continue;
    if (seen[static_cast<std::size_t>(vessel[f])]) return false;
    seen[static_cast<std::size_t>(vessel[f])] = true;
  }
  return true;
}

CellFaces::CellFaces(const TransportGrid& grid) {
  const std::size_t cells = grid.cell_count();
  start.assign(cells + 1, 0);
  for (std::size_t f = 0; f < grid.face_count(); ++f) {
    ++start[static_cast<std::size_t>(grid.a[f]) + 1];
    if (grid.b[f] >= 0) ++start[static_cast<std::size_t>(grid.b[f]) + 1];
  }
  std::size_t sides = 0;
  for (std::size_t c = 0; c < cells; ++c) {
    sides += static_cast<std::size_t>(start[c + 1]);
    if (sides > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
      throw InputError("transport grid: more than 2^31 sides of faces at its cells (" + std::to_string(cells) +
                       " cells): run it over more ranks");
    start[c + 1] = static_cast<std::int32_t>(sides);
  }
  face.resize(sides);
  std::vector<std::int32_t> fill(start.begin(), start.end() - 1);
  for (std::size_t f = 0; f < grid.face_count(); ++f) {
    face[static_cast<std::size_t>(fill[static_cast<std::size_t>(grid.a[f])]++)] = static_cast<std::int32_t>(f);
    if (grid.b[f] >= 0) face[static_cast<std::size_t>(fill[static_cast<std::size_t>(grid.b[f])]++)] = static_cast<std::int32_t>(f);
  }
}

void FlowOrder::update(const TransportGrid& grid, const CellFaces& faces, std::span<const double> volume) {
  const std::size_t cells = grid.cell_count();
  // The flow's directions change only where it reverses or stops: most steps keep the order.
  bool same = direction.size() == grid.face_count() && this->cells.size() == cells;
  direction.resize(grid.face_count());
  for (std::size_t f = 0; f < grid.face_count(); ++f) {
    const signed char d = volume[f] > 0 ? 1 : volume[f] < 0 ? -1 : 0;
    same = same && d == direction[f];
    direction[f] = d;
  }
  if (same) return;
  pending.assign(cells, 0);
  // The cell a face's blood enters, or -1 (a boundary, or no flow, or it comes from a boundary).
  auto downstream = [&](std::size_t f) -> std::int32_t {
    if (volume[f] > 0) return grid.b[f];
    if (volume[f] < 0 && grid.b[f] >= 0) return grid.a[f];
    return -1;
  };
  for (std::size_t f = 0; f < grid.face_count(); ++f) {
    const std::int32_t d = downstream(f);  // a face from a boundary waits for nothing
    if (d >= 0) ++pending[static_cast<std::size_t>(d)];
  }
  this->cells.clear();
  this->cells.reserve(cells);
  for (std::size_t c = 0; c < cells; ++c)
    if (pending[c] == 0) this->cells.push_back(static_cast<std::int32_t>(c));
  for (std::size_t k = 0; k < this->cells.size(); ++k) {
    const auto c = static_cast<std::size_t>(this->cells[k]);
    for (auto i = faces.start[c]; i < faces.start[c + 1]; ++i) {
      const auto f = static_cast<std::size_t>(faces.face[static_cast<std::size_t>(i)]);
      const std::int32_t d = downstream(f);
      if (d < 0 || static_cast<std::size_t>(d) == c) continue;
      if (--pending[static_cast<std::size_t>(d)] == 0) this->cells.push_back(d);
    }
  }
  cyclic = cells - this->cells.size();
  if (cyclic == 0) return;
  for (std::size_t c = 0; c < cells; ++c)
    if (pending[c] != 0) this->cells.push_back(static_cast<std::int32_t>(c));
}

}  // namespace hemotree
