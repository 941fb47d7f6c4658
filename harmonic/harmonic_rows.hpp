// One harmonic's nodal system of a network, as the linear periodic state solves it
// (harmonic/linear_periodic.hpp; internal to harmonic/): what every harmonic shares (the held
// nodes, the system's edges and structure), each vessel's line about the loaded state, a
// harmonic's node terms (boundaries, held ends, a unit diagonal where no edge reaches) and its
// solve with the vessels' two-ports, and the boundaries' Fourier series.
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "boundaries/rcr_outlet.hpp"
#include "boundaries/resistance_outlet.hpp"
#include "core/errors.hpp"
#include "formats/network.hpp"
#include "formats/run_boundaries.hpp"
#include "harmonic/fourier_series.hpp"
#include "harmonic/vessel_line.hpp"
#include "network_flow/harmonic_system.hpp"
#include "physics/poiseuille.hpp"
#include "physics/tube_law.hpp"
#include "physics/viscosity_table.hpp"
#include "steady/steady_flow.hpp"

namespace hemotree {

// What every harmonic shares: the held nodes, the vessels between free nodes (the system's
// edges) and those with one end held, and the system's structure.
struct HarmonicNetwork {
  std::vector<unsigned char> held, touched;
  std::vector<std::int32_t> edge_vessel, held_end_vessel;
  HarmonicSystem system;
};

inline HarmonicNetwork harmonic_network(const Network& net, const RunBoundaries& boundaries) {
  const std::size_t nodes = net.node_count(), n = net.vessel_count();
  std::vector<unsigned char> held(nodes, 0), touched(nodes, 0);  // a node no vessel reaches stays at 0
  for (std::size_t i = 0; i < boundaries.size(); ++i)
    if (boundaries.type(i) == BoundaryType::pressure) held[static_cast<std::size_t>(boundaries.node(i))] = 1;
  std::vector<std::int32_t> a, b, edge_vessel, held_end_vessel;
  for (std::size_t v = 0; v < n; ++v) {
    const auto i = static_cast<std::size_t>(net.from[v]), j = static_cast<std::size_t>(net.to[v]);
    touched[i] = touched[j] = 1;
    if (held[i] && held[j]) continue;
    if (held[i] || held[j]) {
      held_end_vessel.push_back(static_cast<std::int32_t>(v));
    } else {
      a.push_back(net.from[v]);
      b.push_back(net.to[v]);
      edge_vessel.push_back(static_cast<std::int32_t>(v));
    }
  }
  return {std::move(held), std::move(touched), std::move(edge_vessel), std::move(held_end_vessel),
          HarmonicSystem(nodes, std::move(a), std::move(b))};
}

// One harmonic's system, kept from one harmonic to the next: fresh pages of this size cost
// more than the solve.
struct HarmonicWorkspace {
  std::vector<Complex> shunt, current;
  std::vector<TwoPort> edge;  // a block of them on a forest, every one else
  std::vector<HarmonicSystem::Coupling> coupling;  // on a forest
};

// Vessel v's line about the loaded state: its R', L', C' at the lumen of its mean pressure
// (the mean of its nodes'), its length, mean velocity and profile.
struct LineAbout {
  const Network& net;
  std::span<const TubeLaw> laws;
  const ViscosityTable& viscosity;
  const SteadyFlow& steady;
  double k_friction, density;
  VesselLine operator()(std::size_t v) const {
    const TubeLaw& law = laws[v];
    const double p = 0.5 * (steady.node_pressure[static_cast<std::size_t>(net.from[v])] +
                            steady.node_pressure[static_cast<std::size_t>(net.to[v])]);
    const double area = law.area(p), mu = viscosity(area), compliance = law.compliance_per_length(area);
    const double resistance = k_friction * mu / (area * area), velocity = steady.flow[v] / area;
    // mu'(A) by a central difference over 1e-4 of the lumen (the table is a smooth cubic;
    // Newtonian blood: 0).
    const double h = 1e-4 * area, mu_slope = (viscosity(area + h) - viscosity(area - h)) / (2 * h);
    const double kappa = resistance * velocity * compliance * (2 - area * mu_slope / mu);
    return {resistance, density / area, compliance, net.length[v], velocity, law.alpha, kappa};
  }
};

// One harmonic's rows at the nodes, into shunt and current (of every node): the boundaries'
// terms in their order, the currents of extra_current (the mean shift's), the vessels that end
// at a held node, and a unit diagonal where no edge of the system reaches a node: everything
// of the nodal system but its edges' two-ports. line_of(v) gives vessel v's line.
// Some nodes of a network (a share's: the ones its solve reads) and the boundaries at them in
// the boundaries' order, each with its place in the boundaries' series (-1: an outlet), so
// that a harmonic's node terms cost those nodes, not the whole network's (node_terms below).
struct NodeSubset {
  std::vector<std::int32_t> nodes, boundary, series_index;
  NodeSubset(const RunBoundaries& boundaries, std::span<const std::int32_t> subset, std::size_t node_count)
      : nodes(subset.begin(), subset.end()) {
    std::vector<unsigned char> in(node_count, 0);
    for (const std::int32_t node : nodes) in[static_cast<std::size_t>(node)] = 1;
    std::int32_t next = 0;
    for (std::size_t i = 0; i < boundaries.size(); ++i) {
      const std::int32_t place = boundaries.is_outlet(i) ? -1 : next++;
      if (!in[static_cast<std::size_t>(boundaries.node(i))]) continue;
      boundary.push_back(static_cast<std::int32_t>(i));
      series_index.push_back(place);
    }
  }
};

// Boundary i's term in its node's row at harmonic k (series_place: its place in series, -1:
// an outlet).
inline void boundary_term(const Network& net, const RunBoundaries& boundaries, const std::vector<FourierSeries>& series,
                          std::size_t i, std::int32_t series_place, int k, double w, std::vector<Complex>& shunt,
                          std::vector<Complex>& current) {
  const auto node = static_cast<std::size_t>(boundaries.node(i));
  const Complex amplitude =
      series_place < 0 ? Complex(0.0) : series[static_cast<std::size_t>(series_place)].amplitude[static_cast<std::size_t>(k)];
  const Outlet& o = boundaries.outlet(i);
  switch (boundaries.type(i)) {
    case BoundaryType::flow: current[node] += amplitude; break;
    case BoundaryType::pressure: current[node] = amplitude; break;
    case BoundaryType::resistance: shunt[node] += 1.0 / ResistanceOutlet{o.r, o.p_out}.impedance(w); break;
    case BoundaryType::rcr: shunt[node] += 1.0 / RcrOutlet{o.r1, o.c, o.r2, o.p_out}.impedance(w); break;
    case BoundaryType::reflection:
      throw InputError("node " + std::to_string(net.node_id[node]) + ": a reflection outlet has no steady state to linearise about");
  }
}

// subset: where given, the rows of its nodes alone, each the whole's (the other entries of
// shunt and current are left as they were; the arrays are sized to every node once).
template <class LineOf>
void node_terms(const Network& net, const HarmonicNetwork& h, const RunBoundaries& boundaries,
                const std::vector<FourierSeries>& series, const LineOf& line_of, int k, double w,
                std::vector<Complex>& shunt, std::vector<Complex>& current, std::span<const double> extra_current,
                const NodeSubset* subset = nullptr) {
  const std::size_t nodes = net.node_count();
  // A held node's current is its held pressure: nothing else flows into it (one boundary a
  // node; a vessel to it draws its current at its other node), and its row is x = current.
  if (!subset) {
    shunt.assign(nodes, 0.0), current.assign(nodes, 0.0);
    std::int32_t next = 0;  // series holds the boundaries' that are not outlets, in their order
    for (std::size_t i = 0; i < boundaries.size(); ++i)
      boundary_term(net, boundaries, series, i, boundaries.is_outlet(i) ? -1 : next++, k, w, shunt, current);
    for (std::size_t node = 0; node < extra_current.size(); ++node)
      if (!h.held[node]) current[node] += extra_current[node];
  } else {
    if (shunt.size() != nodes) shunt.assign(nodes, 0.0), current.assign(nodes, 0.0);
    for (const std::int32_t node : subset->nodes) shunt[static_cast<std::size_t>(node)] = current[static_cast<std::size_t>(node)] = 0.0;
    for (std::size_t j = 0; j < subset->boundary.size(); ++j)
      boundary_term(net, boundaries, series, static_cast<std::size_t>(subset->boundary[j]), subset->series_index[j], k, w,
                    shunt, current);
    if (!extra_current.empty())
      for (const std::int32_t node : subset->nodes)
        if (!h.held[static_cast<std::size_t>(node)]) current[static_cast<std::size_t>(node)] += extra_current[static_cast<std::size_t>(node)];
  }
  // A vessel ending at a held node becomes, at its other node, a shunt and the current the
  // held pressure drives through it.
  for (const std::int32_t vessel : h.held_end_vessel) {
    const auto v = static_cast<std::size_t>(vessel);
    const TwoPort y = line_of(v).two_port(w);
    const auto i = static_cast<std::size_t>(net.from[v]), j = static_cast<std::size_t>(net.to[v]);
    if (h.held[i]) {
      shunt[j] += y.bb;
      current[j] -= y.ba * current[i];
    } else {
      shunt[i] += y.aa;
      current[i] -= y.ab * current[j];
    }
  }
  auto unreached = [&](std::size_t node) {  // no edge of the system reaches it
    if (h.held[node] || !h.touched[node]) shunt[node] = 1.0;
  };
  if (!subset) {
    for (std::size_t node = 0; node < nodes; ++node) unreached(node);
  } else {
    for (const std::int32_t node : subset->nodes) unreached(static_cast<std::size_t>(node));
  }
}

// The network's oscillation at one angular frequency w: every node's pressure amplitude,
// left in work.current; line_of(v) gives vessel v's line. threads: the vessels' two-ports
// built in parallel (each its own: the same numbers for any count).
template <class LineOf>
void solve_harmonic(const Network& net, const HarmonicNetwork& h, const RunBoundaries& boundaries,
                    const std::vector<FourierSeries>& series, const LineOf& line_of, int k, double w,
                    HarmonicWorkspace& work, int threads = 1, std::span<const double> extra_current = {}) {
  std::vector<Complex>&shunt = work.shunt, &current = work.current;
  node_terms(net, h, boundaries, series, line_of, k, w, shunt, current, extra_current);
  std::vector<TwoPort>& edge = work.edge;
  const std::size_t edges = h.edge_vessel.size();
  // Two-ports built in parallel, a block of edges at a time on a forest (its elimination
  // keeps 32 of their 64 bytes, the diagonals summed in the edges' order as the whole solve
  // sums them: the same numbers), all at once on any other graph.
  const std::size_t block = h.system.forest() ? std::min<std::size_t>(edges, 1 << 16) : edges;
  edge.resize(block);
  if (h.system.forest()) work.coupling.resize(edges);
  const std::span<const std::int32_t> a = h.system.edge_a(), b = h.system.edge_b();
  for (std::size_t first = 0; first < edges; first += block) {
    const auto count = static_cast<std::int64_t>(std::min(block, edges - first));
#pragma omp parallel for schedule(static) num_threads(threads) if (threads > 1)
    for (std::int64_t j = 0; j < count; ++j)
      edge[static_cast<std::size_t>(j)] = line_of(static_cast<std::size_t>(h.edge_vessel[first + static_cast<std::size_t>(j)])).two_port(w);
    if (!h.system.forest()) break;
    for (std::size_t j = 0; j < static_cast<std::size_t>(count); ++j) {
      const std::size_t e = first + j;
      shunt[static_cast<std::size_t>(a[e])] += edge[j].aa;
      shunt[static_cast<std::size_t>(b[e])] += edge[j].bb;
      work.coupling[e] = {edge[j].ab, edge[j].ba};
    }
  }
  try {
    if (h.system.forest()) {
      h.system.solve_forest_in_place(work.coupling, shunt, current);
    } else {
      h.system.solve_in_place(edge, shunt, current);
    }
  } catch (const std::invalid_argument&) {
    throw InputError("the linear periodic solution: a part of the network has no path to an outlet or a pressure");
  }
}

// The boundaries' Fourier series (an outlet's pressure beyond does not oscillate: none).
inline std::vector<FourierSeries> boundary_series(const RunBoundaries& boundaries, int harmonics) {
  std::vector<FourierSeries> series;
  for (std::size_t i = 0; i < boundaries.size(); ++i)
    if (!boundaries.is_outlet(i)) series.push_back(fourier_series(boundaries.waveform(i), harmonics));
  return series;
}

}  // namespace hemotree
