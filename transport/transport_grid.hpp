// The finite volumes that red cells and tracers move through, and the order a step visits
// them in.
//
// A cell is a slice of a 1D vessel, a node of 0D vessels (it holds half of each, as the 0D
// model's node volumes do), or a junction of 1D vessels (no volume: what flows in flows out).
// A face joins two cells, or a cell and a boundary of the network. A step hands the volume
// of blood each face passed (signed: positive from its cell `a` to `b`); the cells' volumes
// follow from them (V+ = V + in - out), so the scheme's own volumes close exactly and the
// flow solver's volumes are met where its fluxes are conservative (docs/transport.md).
//
// The schemes are implicit upwind (backward Euler): a cell's new value depends on the new
// values upstream, so cells are visited in flow order, found each step by Kahn's algorithm on
// the faces' signs. Cells on a directed cycle of the flow (an instant of circulation in a
// loop) are left for a Gauss-Seidel iteration.
//
// A run over ranks (docs/transport.md, "Over MPI ranks") cuts the grid where a rank's subtrees
// hang from the top's: each side holds the face between them, to a cut of its own, a
// boundary whose inflow is the other side's (its cell's hematocrit and the phase separation's
// share there), exchanged once a step in flow order.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/array_bytes.hpp"

namespace hemotree {

struct TransportGrid {
  // Per cell: the network node it is (node cells and junctions), or -1 for a vessel's slice;
  // and the Fahraeus parameter k of its lumen (physics/phase_separation.hpp:
  // H_T = H_D (k + (1 - k) H_D); 1 where the effect is off).
  std::vector<std::int32_t> node;
  std::vector<double> fahraeus;
  // Per face: its two sides. b < 0 is boundary -1 - b (a place in the run's boundary list).
  std::vector<std::int32_t> a, b;
  // Per face: the vessel whose lumen it lies in (-1: none, a boundary's own face), and that
  // lumen's diameter there [m] (the phase separation law reads it).
  std::vector<std::int32_t> vessel;
  std::vector<double> diameter;
  std::size_t boundaries = 0;
  // The last `cuts` of the boundaries are cuts (a run over ranks): the network's boundaries
  // are the first boundaries - cuts.
  std::size_t cuts = 0;

  bool is_cut(std::size_t boundary) const { return boundary + cuts >= boundaries; }
  std::size_t cell_count() const { return node.size(); }
  std::size_t face_count() const { return a.size(); }
  void add_cell(std::int32_t network_node, double fahraeus_k) {
    node.push_back(network_node);
    fahraeus.push_back(fahraeus_k);
  }
  void add_face(std::int32_t from_cell, std::int32_t to_cell, std::int32_t in_vessel, double lumen_diameter) {
    a.push_back(from_cell);
    b.push_back(to_cell);
    vessel.push_back(in_vessel);
    diameter.push_back(lumen_diameter);
  }
  // Once every cell and face is added: each array's spare capacity freed (grown by
  // doubling: 12 MB of the million-vessel tree's grid).
  void shrink_to_fit() {
    node.shrink_to_fit();
    fahraeus.shrink_to_fit();
    a.shrink_to_fit();
    b.shrink_to_fit();
    vessel.shrink_to_fit();
    diameter.shrink_to_fit();
  }
  static std::int32_t boundary_side(std::size_t boundary) { return -1 - static_cast<std::int32_t>(boundary); }
  // The faces of face f's vessel from f on end at the returned face: a vessel's faces lie one
  // after another where the grid is built so (faces_by_vessel), and a vessel's sums over them
  // need no per-vessel accumulator.
  std::size_t vessel_faces_end(std::size_t f) const {
    std::size_t end = f + 1;
    while (end < vessel.size() && vessel[end] == vessel[f]) ++end;
    return end;
  }
  // Whether every vessel's faces lie one after another (the faces of no vessel, -1, anywhere).
  bool faces_by_vessel() const;
  std::size_t bytes() const { return arrays_bytes(node, fahraeus, a, b, vessel, diameter); }
};

// Each cell's faces (compressed rows): the faces of cell c are face[start[c] .. start[c + 1]).
// 32-bit like the faces' numbers themselves (a grid of more than 2^31 face sides is refused).
struct CellFaces {
  std::vector<std::int32_t> start;
  std::vector<std::int32_t> face;
  explicit CellFaces(const TransportGrid& grid);
  std::size_t bytes() const { return arrays_bytes(start, face); }
};

// The cells in an order in which every cell comes after the cells its inflows come from (the
// blood passed through each face this step: volume[f]), as far as the flow has one; the
// cells on or below a directed cycle come last (`cyclic` of them).
struct FlowOrder {
  std::vector<std::int32_t> cells;
  std::size_t cyclic = 0;
  // Scratch kept between steps: inflowing faces not yet visited, per cell; each face's
  // direction at the last update (the order stands while no face changes it).
  std::vector<std::int32_t> pending;
  std::vector<signed char> direction;
  void update(const TransportGrid& grid, const CellFaces& faces, std::span<const double> volume);
  std::size_t bytes() const { return arrays_bytes(cells, pending, direction); }
};

}  // namespace hemotree
