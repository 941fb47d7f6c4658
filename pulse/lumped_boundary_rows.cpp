// The boundary conditions at nodes of 0D vessels as rows of the 0D system, built once by the
// constructor (the 1D ends take the same conditions in pulse/dg_rate.cpp), and which of them
// count as entering the network.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "boundaries/rcr_outlet.hpp"
#include "boundaries/resistance_outlet.hpp"
#include "boundaries/system_rows.hpp"
#include "core/errors.hpp"
#include "core/setting_error.hpp"
#include "pulse/lumped_vessels.hpp"
#include "pulse/network_boundaries.hpp"

namespace hemotree {

void LumpedVessels::add_boundary_rows(const Network& net, std::span<const TubeLaw> laws,
                                      const ViscosityTable& viscosity) {
  // Boundary conditions at nodes of 0D vessels (pulse/network_boundaries.hpp's order):
  // outlets are shunts, or R1 to a capacitor node with R2 and C; flows are currents into
  // their nodes; a pressure holds its node through a shunt far stiffer than the node's
  // vessel (predict() sizes it), a Dirichlet condition to 1e-10 of the vessel's drop.
  std::vector<std::int32_t> vessel_at(net.node_count(), -1), end_sign(net.node_count(), 0);
  for (std::size_t e = 0; e < vessels_.size(); ++e) {
    const auto v = static_cast<std::size_t>(vessels_[e]);
    vessel_at[static_cast<std::size_t>(net.from[v])] = static_cast<std::int32_t>(v);
    end_sign[static_cast<std::size_t>(net.from[v])] = -1;  // flow along it leaves the node
    vessel_at[static_cast<std::size_t>(net.to[v])] = static_cast<std::int32_t>(v);
    end_sign[static_cast<std::size_t>(net.to[v])] = 1;
  }
  const RunBoundaries boundaries(net);
  std::size_t outlet_count = 0;
  for (std::size_t i = 0; i < boundaries.size(); ++i) outlet_count += boundaries.is_outlet(i) ? 1 : 0;
  capacitor_of_outlet_.assign(outlet_count, -1);
  std::int32_t k = -1;  // outlet index
  for (std::size_t i = 0; i < boundaries.size(); ++i) {
    const NodeBoundary bc = boundaries[i];
    if (bc.is_outlet()) ++k;
    const auto network_node = static_cast<std::size_t>(bc.node);
    if (node_of_[network_node] < 0 || is_ghost_node(static_cast<std::size_t>(node_of_[network_node]))) continue;  // another rank's
    const auto at = static_cast<std::size_t>(node_of_[network_node]);
    const auto v = static_cast<std::size_t>(vessel_at[network_node]);
    const auto boundary = static_cast<std::int32_t>(i);
    if (bc.type == BoundaryType::flow) {
      inflow_node_.push_back(static_cast<std::int32_t>(at));
      inflow_boundary_.push_back(boundary);
      continue;
    }
    if (bc.type == BoundaryType::pressure) {
      held_node_.push_back(static_cast<std::int32_t>(at));
      held_boundary_.push_back(boundary);
      const TubeLaw& law = laws[v];
      held_reference_conductance_.push_back(law.reference_area * law.reference_area /
                                            (friction_k_ * viscosity(law.reference_area) * net.length[v]));
      shunt_pressure_[at] = bc.waveform.mean_value();
      continue;
    }
    const Outlet& o = bc.outlet;
    if (o.type == BoundaryType::reflection)
      throw SettingError("model", "vessel " + std::to_string(net.id[v]) + ": a reflection outlet needs a 1D vessel (" +
                                      placeholder("model") + " 1d, or auto, keeps it 1D)");
    // The outlet's rows (boundaries/resistance_outlet.hpp, rcr_outlet.hpp).
    const RcrOutlet rcr{o.r1, o.c, o.r2, o.p_out};
    if (o.type == BoundaryType::rcr && o.c > 0) {
      const LumpedCapacitor rows = rcr.lumped_capacitor();
      capacitor_of_outlet_[static_cast<std::size_t>(k)] = static_cast<std::int32_t>(outlet_of_capacitor_.size());
      const auto c = static_cast<std::int32_t>(nodes_++);
      rcr_outlet_boundary_.push_back({boundary, static_cast<std::int32_t>(vessel_edges_ + outlet_of_capacitor_.size())});
      outlet_of_capacitor_.push_back(k);
      // The vessel's section at the outlet: its first at `from`, its last at `to`.
      const auto index = static_cast<std::size_t>(index_of_vessel_[v]);
      capacitor_vessel_edge_.push_back(static_cast<std::int32_t>(end_sign[network_node] < 0 ? first_edge(index) : first_edge(index + 1) - 1));
      capacitor_edge_sign_.push_back(end_sign[network_node]);
      a_.push_back(static_cast<std::int32_t>(at));
      b_.push_back(c);
      edge_fixed_resistance_.push_back(rows.edge_resistance);
      shunt_.push_back(rows.shunt.conductance);
      shunt_pressure_.push_back(rows.shunt.pressure);
      volume_b_.push_back(static_cast<float>(rows.compliance));
    } else {
      const LumpedShunt row = o.type == BoundaryType::rcr ? rcr.series_lumped_shunt()
                                                          : ResistanceOutlet{o.r, o.p_out}.lumped_shunt();
      shunt_[at] = row.conductance;
      shunt_pressure_[at] = row.pressure;
      outlet_boundary_.push_back({boundary, static_cast<std::int32_t>(at)});
    }
  }
  // By node: complete() reads each outlet's node, in the arrays' order.
  std::stable_sort(outlet_boundary_.begin(), outlet_boundary_.end(),
                   [](const OutletNode& x, const OutletNode& y) { return x.node < y.node; });
  if (!held_node_.empty()) {
    held_.assign(nodes_, 0);
    for (std::size_t j = 0; j < held_node_.size(); ++j) held_[static_cast<std::size_t>(held_node_[j])] = static_cast<std::int32_t>(j + 1);
    held_out_.assign(held_node_.size(), 0.0);
  }
}

std::vector<std::int32_t> LumpedVessels::boundaries() const {
  std::vector<std::int32_t> out(inflow_boundary_.begin(), inflow_boundary_.end());
  out.insert(out.end(), held_boundary_.begin(), held_boundary_.end());
  for (const OutletNode& o : outlet_boundary_) out.push_back(o.boundary);
  for (const OutletEdge& o : rcr_outlet_boundary_) out.push_back(o.boundary);
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace hemotree
