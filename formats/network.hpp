// The vascular network: nodes joined by straight vessels, stored as flat arrays
// (structure of arrays) so that every stage can sweep millions of vessels cheaply.
// SI units throughout: metres, pascals.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "formats/boundary_conditions.hpp"

namespace hemotree {

// Vessel classes by reference lumen diameter (the paper's Table 1 ranges).
enum class VesselClass : std::uint8_t { artery, small_artery, arteriole, capillary };
inline constexpr int vessel_class_count = 4;

inline constexpr double artery_min_diameter = 500e-6;       // D >= 500 um
inline constexpr double small_artery_min_diameter = 100e-6; // 100 <= D < 500 um
inline constexpr double arteriole_min_diameter = 10e-6;     // 10 <= D < 100 um; below: capillary

VesselClass classify(double diameter);
std::string_view to_string(VesselClass c);
std::optional<VesselClass> parse_vessel_class(std::string_view name);

struct Network {
  // Nodes. Coordinates are optional: either all nodes have them or none.
  std::vector<std::int64_t> node_id;
  std::vector<double> x, y, z;

  // Vessels. `from` and `to` index the node arrays; flow is positive from -> to.
  std::vector<std::int64_t> id;
  std::vector<std::int32_t> from, to;
  std::vector<double> length;          // [m]
  std::vector<double> diameter;        // reference lumen diameter [m] (at `from` if tapered)
  std::vector<double> wall_thickness;  // [m]
  std::vector<double> youngs_modulus;  // [Pa]
  std::vector<std::int32_t> generation;  // root = 0
  std::vector<VesselClass> vessel_class;
  // A tube law given directly, p = p_ref + beta (sqrt(A) - sqrt(A_ref)) with A_ref from the
  // diameter (benchmark cases): empty when no vessel has one, NaN for a vessel without.
  std::vector<double> beta;                // [Pa/m]
  std::vector<double> reference_pressure;  // [Pa]
  // Tapered vessels (format version 2): the reference lumen diameter at the `to` end, the
  // lumen varying linearly from `diameter` at `from`: empty when no vessel tapers, NaN for
  // a vessel that does not.
  std::vector<double> distal_diameter;     // [m]

  // For flow computations: blood and the boundary conditions. A tree's (vprune's: format
  // version 1) are the inflow at its root and the 0D outlets of its terminal vessels
  // (sparse: one entry per outlet, sorted by vessel index); any network's (version 2) are
  // conditions at nodes, one per node at most, sorted by node. A file may have both forms;
  // node_boundaries() gives them as one list.
  std::optional<Blood> blood;
  std::optional<Inlet> inlet;
  std::vector<Outlet> outlets;
  std::vector<NodeBoundary> boundaries;

  // Small metadata kept as JSON: who made the file and how, and top-level members this
  // version does not know, passed through untouched.
  nlohmann::json provenance = nlohmann::json::object();
  nlohmann::json extra = nlohmann::json::object();

  std::size_t vessel_count() const { return id.size(); }
  std::size_t node_count() const { return node_id.size(); }
  bool has_coordinates() const { return !x.empty(); }

  void reserve(std::size_t vessels, std::size_t nodes);
  // Every array's capacity to its size: a reader that grew them by doubling holds up to twice
  // what it read (a 10-million-vessel tree: 1.6 times) until then.
  void shrink_to_fit();
  std::int32_t add_node(std::int64_t node_id_value);
  std::int32_t add_node(std::int64_t node_id_value, double px, double py, double pz);
  // Appends a vessel between node indices; the class follows from the diameter.
  std::size_t add_vessel(std::int64_t vessel_id, std::int32_t from_node, std::int32_t to_node,
                         double length_m, double diameter_m, double wall_thickness_m,
                         double youngs_modulus_pa, std::int32_t generation_index);

  bool is_tapered(std::size_t vessel) const {
    return !distal_diameter.empty() && !(distal_diameter[vessel] != distal_diameter[vessel]);
  }
  // The reference lumen diameter at `to` (`diameter` unless the vessel tapers).
  double diameter_at_to(std::size_t vessel) const {
    return is_tapered(vessel) ? distal_diameter[vessel] : diameter[vessel];
  }
  // The mean of its two ends' reference diameters (a tapered vessel's; `diameter` otherwise).
  double mean_diameter(std::size_t vessel) const { return 0.5 * (diameter[vessel] + diameter_at_to(vessel)); }
  double volume(std::size_t vessel) const;  // pi/4 l (D0^2 + D0 D1 + D1^2)/3: a cone's frustum [m^3]
  // Vessel index of an id (linear search unless ids equal indices); -1 when absent.
  std::int64_t index_of(std::int64_t vessel_id) const;
};

// Wave propagation (vprune's outlet calibration, hemosolve) needs a tube law for every
// vessel: "wall_thickness" and "youngs_modulus", or "beta" and "reference_pressure". The
// format leaves them optional (vstats needs neither), so the tools that need them call this
// before any work. Throws InputError "SOURCE: vessel ID: missing \"wall_thickness\" ..."
// naming the first vessel without one.
void require_tube_laws(const Network& net, const std::string& source);

// The tree form's conditions as conditions at nodes: an outlet at its vessel's `to` node
// (its vessel kept in outlet.vessel), the inlet as a flow into its vessel's `from` node
// (InputError for an inlet of no vessel).
NodeBoundary as_node_boundary(const Network& net, const Outlet& outlet);
NodeBoundary as_node_boundary(const Network& net, const Inlet& inlet);

// Every boundary condition of the network at its node, sorted by node: the version 2 node
// boundaries, the inlet (a flow into its vessel's `from` node) and the outlets (at their
// vessels' `to` nodes). Throws InputError when two land on one node.
std::vector<NodeBoundary> node_boundaries(const Network& net);

// A reader's last step with the boundaries at nodes: sorted by node (equal nodes in the
// file's order), then checked as check_one_boundary_per_node checks them.
void sort_boundaries_by_node(Network& net);

// Throws InputError when two boundary conditions land on one node (naming the lowest such
// node and its first two in node_boundaries' order), or for an inlet of no vessel. The run's
// list of them, in its order: formats/run_boundaries.hpp.
void check_one_boundary_per_node(const Network& net);

// The waveform that sets the run's period and pulse: the tree form's inlet, else the first
// time-varying flow or pressure of run_boundaries, else a constant of period 1 s. Throws
// InputError (naming both nodes) where two time-varying boundaries have different periods.
Waveform driving_waveform(const Network& net);

}  // namespace hemotree
