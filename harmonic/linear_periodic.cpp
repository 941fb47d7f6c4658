#include "harmonic/linear_periodic.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <exception>
#include <functional>
#include <iterator>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>

#include <omp.h>

#include "boundaries/rcr_outlet.hpp"
#include "boundaries/resistance_outlet.hpp"
#include "core/errors.hpp"
#include "harmonic/mean_shift.hpp"
#include "network_flow/harmonic_system.hpp"
#include "physics/poiseuille.hpp"

namespace hemotree {

namespace {

// What every harmonic shares: the held nodes, the vessels between free nodes (the system's
// edges) and those with one end held, and the system's structure.
struct HarmonicNetwork {
  std::vector<unsigned char> held, touched;
  std::vector<std::int32_t> edge_vessel, held_end_vessel;
  HarmonicSystem system;
};

HarmonicNetwork harmonic_network(const Network& net, const RunBoundaries& boundaries) {
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
template <class LineOf>
void node_terms(const Network& net, const HarmonicNetwork& h, const RunBoundaries& boundaries,
                const std::vector<FourierSeries>& series, const LineOf& line_of, int k, double w,
                std::vector<Complex>& shunt, std::vector<Complex>& current, std::span<const double> extra_current) {
  const std::size_t nodes = net.node_count();
  // A held node's current is its held pressure: nothing else flows into it (one boundary a
  // node; a vessel to it draws its current at its other node), and its row is x = current.
  shunt.assign(nodes, 0.0), current.assign(nodes, 0.0);
  std::size_t next = 0;  // series holds the boundaries' that are not outlets, in their order
  for (std::size_t i = 0; i < boundaries.size(); ++i) {
    const auto node = static_cast<std::size_t>(boundaries.node(i));
    const Complex amplitude = boundaries.is_outlet(i) ? Complex(0.0) : series[next++].amplitude[static_cast<std::size_t>(k)];
    const Outlet& o = boundaries.outlet(i);
    switch (boundaries.type(i)) {
      case BoundaryType::flow: current[node] += amplitude; break;
      case BoundaryType::pressure: current[node] = amplitude; break;
      case BoundaryType::resistance: shunt[node] += 1.0 / ResistanceOutlet{o.r, o.p_out}.impedance(w); break;
      case BoundaryType::rcr: shunt[node] += 1.0 / RcrOutlet{o.r1, o.c, o.r2, o.p_out}.impedance(w); break;
      case BoundaryType::reflection:
        throw InputError("node " + std::to_string(net.node_id[node]) +
                         ": a reflection outlet has no steady state to linearise about");
    }
  }
  for (std::size_t node = 0; node < extra_current.size(); ++node)
    if (!h.held[node]) current[node] += extra_current[node];
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
  for (std::size_t node = 0; node < nodes; ++node) {
    if (h.held[node] || !h.touched[node]) shunt[node] = 1.0;  // no edge of the system reaches it
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

}  // namespace

VesselLine loaded_line(const Network& net, const Blood& blood, std::span<const TubeLaw> laws,
                       const ViscosityTable& viscosity, const SteadyFlow& steady, std::size_t v) {
  return LineAbout{net, laws, viscosity, steady, friction_coefficient(blood.alpha), blood.density}(v);
}

LinearPeriodic solve_linear_periodic(const Network& net, const Blood& blood, std::span<const TubeLaw> laws,
                                     const ViscosityTable& viscosity, int harmonics, int threads,
                                     const std::function<bool(const VesselLine&)>& shift_source) {
  const SteadyFlow steady =
      solve_distended_steady_flow(net, blood, laws, viscosity, net.inlet ? net.inlet->waveform.mean_value() : 0.0, nullptr,
                                  threads);
  return solve_linear_periodic(net, blood, laws, viscosity, steady, RunBoundaries(net), harmonics, threads, shift_source);
}

LinearPeriodic LinearPeriodic::about(const Network& net, const Blood& blood, std::span<const TubeLaw> laws,
                                     const ViscosityTable& viscosity, const SteadyFlow& steady, int threads) {
  const std::size_t n = net.vessel_count();
  LinearPeriodic out;
  out.net_ = &net;
  out.period_ = driving_waveform(net).period;
  out.mean_node_pressure_ = steady.node_pressure;
  out.mean_flow_ = steady.flow;
  const LineAbout line_about{net, laws, viscosity, steady, friction_coefficient(blood.alpha), blood.density};
  out.line_.resize(n);
  const auto vessels = static_cast<std::int64_t>(n);
#pragma omp parallel for schedule(static) num_threads(threads) if (threads > 1)
  for (std::int64_t i = 0; i < vessels; ++i) out.line_[static_cast<std::size_t>(i)] = line_about(static_cast<std::size_t>(i));
  return out;
}

namespace {

// The boundaries' Fourier series (an outlet's pressure beyond does not oscillate: none).
std::vector<FourierSeries> boundary_series(const RunBoundaries& boundaries, int harmonics) {
  std::vector<FourierSeries> series;
  for (std::size_t i = 0; i < boundaries.size(); ++i)
    if (!boundaries.is_outlet(i)) series.push_back(fourier_series(boundaries.waveform(i), harmonics));
  return series;
}

// Solves harmonics 1 .. K (those of `series`) of the network about `lines`, all at once (one
// to a thread), and hands each one's node amplitudes to consume(k, amplitudes) in the order of
// k, so that what the caller keeps is in one order whatever the threads. The lowest harmonic
// that fails is the one thrown.
template <class Consume>
void solve_harmonics(const Network& net, const HarmonicNetwork& network, const LinearPeriodic& lines,
                     const RunBoundaries& boundaries, const std::vector<FourierSeries>& series, int harmonics,
                     int threads, Consume&& consume) {
  std::vector<HarmonicWorkspace> work(static_cast<std::size_t>(std::max(threads, 1)));
  std::vector<std::vector<Complex>> solved(static_cast<std::size_t>(harmonics));
  std::vector<std::exception_ptr> failure(solved.size());
#pragma omp parallel num_threads(threads) if (threads > 1)
  {
    HarmonicWorkspace& mine = work[static_cast<std::size_t>(omp_get_thread_num())];
#pragma omp for schedule(dynamic, 1)
    for (int k = 1; k <= harmonics; ++k) {
      try {
        solve_harmonic(net, network, boundaries, series, [&](std::size_t v) -> const VesselLine& { return lines.line(v); },
                       k, lines.omega(k), mine);
        solved[static_cast<std::size_t>(k - 1)] = mine.current;
      } catch (...) {
        failure[static_cast<std::size_t>(k - 1)] = std::current_exception();
      }
    }
  }
  for (const std::exception_ptr& f : failure)
    if (f) std::rethrow_exception(f);
  for (int k = 1; k <= harmonics; ++k) consume(k, std::move(solved[static_cast<std::size_t>(k - 1)]));
}

}  // namespace

namespace {

// The vessels a loop runs over, in increasing order: those listed, or every one of `all`.
struct VesselList {
  const std::vector<std::int32_t>* listed = nullptr;
  std::size_t all = 0;
  std::size_t size() const { return listed ? listed->size() : all; }
  std::size_t operator[](std::size_t i) const { return listed ? static_cast<std::size_t>((*listed)[i]) : i; }
};

// value(v) for every vessel v of the list, a block at a time in parallel, each handed to
// consume(v, value) in the list's order: a loop that adds into shared sums keeps its
// one-thread order (and bits) without an array of a value a vessel.
template <class Value, class Consume>
void in_blocks(const VesselList& vessels, int threads, const Value& value, const Consume& consume) {
  const std::size_t n = vessels.size();
  std::vector<double> block(std::min<std::size_t>(n, std::size_t{1} << 16));
  for (std::size_t first = 0; first < n; first += block.size()) {
    const std::size_t count = std::min(block.size(), n - first);
#pragma omp parallel for schedule(static) num_threads(threads) if (threads > 1)
    for (std::int64_t j = 0; j < static_cast<std::int64_t>(count); ++j)
      block[static_cast<std::size_t>(j)] = value(vessels[first + static_cast<std::size_t>(j)]);
    for (std::size_t j = 0; j < count; ++j) consume(vessels[first + j], block[j]);
  }
}

// The tube law's curvature and the friction's lumen of vessel v at its line's lumen
// (harmonic/mean_shift.hpp): R'(A) = k mu(A) / A^2 differentiated over 1e-3 of the lumen.
LumenSlopes lumen_slopes(const TubeLaw& law, const ViscosityTable& viscosity, double k_friction, double area) {
  auto resistance = [&](double a) { return k_friction * viscosity(a) / (a * a); };
  const double h = 1e-3 * area, r = resistance(area), up = resistance(area + h), down = resistance(area - h);
  const double root_slope = law.lumen_root_slope();  // the lumen's root is linear in p: A'' = 2 (d sqrt(A)/dp)^2
  return {2 * root_slope * root_slope, (up - down) / (2 * h), (up - 2 * r + down) / (h * h)};
}

// The mean's second-order shift (harmonic/mean_shift.hpp): the forcing of
// every vessel in `sourced` (the 1D ones) and their ends' kinetic pressures at junctions, in
// one nodal system at w = 0 of every vessel's line and every outlet's resistance, the inflow
// and the held pressures fixed. A node's unknown is its static pressure where a boundary or
// a 0D vessel meets it (the 1D ends there add the 0D vessels' flow-weighted kinetic
// pressure, as pulse/lumped_vessels does), else the total pressure its 1D ends share.
// `along` holds the harmonics of the sourced vessels and of the 0D vessels beside their
// ends. Adds each node's shift to node_pressure and hands every vessel's to
// apply(v, dq, profile, dx_from, dx_to): its flow's, its static pressure's along it where it
// is sourced (sampled evenly from `from` to `to`; else empty: its nodes') and its nodes'.
//   Over a share of the network (HarmonicShare), `held` lists the vessels whose terms it sums
// and `answered` those it hands to apply (each list every vessel where it is null), and
// solve_at_zero(current) solves the system at w = 0 with the mean shift's currents (every
// node's array, the share's nodes' entries set), returning the potentials there.
template <class SolveAtZero, class Apply>
void solve_mean_shift(const Network& net, const Blood& blood, std::span<const TubeLaw> laws, const ViscosityTable& viscosity,
                      const RunBoundaries& boundaries, const LineAbout& line_of, const LinearPeriodic& along,
                      const std::vector<bool>& sourced, std::span<const double> node_variance,
                      std::vector<double>& node_pressure, int threads, const VesselList& held,
                      const VesselList& answered, SolveAtZero&& solve_at_zero, Apply&& apply) {
  const std::size_t nodes = net.node_count(), n = net.vessel_count();
  const double k_friction = friction_coefficient(blood.alpha), rho = blood.density;
  // Per node, a byte: a junction (two ends or more, no boundary), and a 1D end there.
  constexpr unsigned char ends_one = 1, ends_more = 2, bounded = 4, one_d = 8;
  std::vector<unsigned char> kind(nodes, 0);
  for (std::size_t v = 0; v < n; ++v)
    for (const std::int64_t end : {net.from[v], net.to[v]}) {
      unsigned char& k = kind[static_cast<std::size_t>(end)];
      k |= (k & (ends_one | ends_more)) ? ends_more : ends_one;
      if (sourced[v]) k |= one_d;
    }
  for (std::size_t i = 0; i < boundaries.size(); ++i) kind[static_cast<std::size_t>(boundaries.node(i))] |= bounded;
  auto junction = [&](std::size_t node) { return (kind[node] & ends_more) && !(kind[node] & bounded); };
  const int harmonics = along.harmonics();
  std::vector<double> omega(static_cast<std::size_t>(harmonics));
  for (int k = 1; k <= harmonics; ++k) omega[static_cast<std::size_t>(k - 1)] = along.omega(k);
  std::vector<Complex> at_from(omega.size()), at_to(omega.size());
  auto pulse_of = [&](std::size_t v) {
    for (int k = 1; k <= harmonics; ++k) {
      at_from[static_cast<std::size_t>(k - 1)] = along.node_pressure(k, static_cast<std::size_t>(net.from[v]));
      at_to[static_cast<std::size_t>(k - 1)] = along.node_pressure(k, static_cast<std::size_t>(net.to[v]));
    }
  };
  auto slopes_of = [&](std::size_t v) { return lumen_slopes(laws[v], viscosity, k_friction, rho / along.line(v).inertance); };
  auto kinetic = [&](std::size_t v, double x) {
    pulse_of(v);
    return mean_kinetic_pressure(along.line(v), slopes_of(v), rho, pulse_moments(along.line(v), omega, at_from, at_to, x));
  };
  // The 0D vessels' kinetic pressure at the junctions of 1D ends, weighted by their mean flows
  // (the vessels `along` holds beside the 1D ends): sum and weight per node.
  std::unordered_map<std::size_t, std::array<double, 2>> beside;
  for (std::size_t i = 0; i < held.size(); ++i) {
    const std::size_t v = held[i];
    if (sourced[v] || !along.holds(v)) continue;
    for (const bool distal : {false, true}) {
      const auto node = static_cast<std::size_t>(distal ? net.to[v] : net.from[v]);
      if (!junction(node) || !(kind[node] & one_d)) continue;
      const double w = std::abs(along.line(v).mean_velocity) + 1e-300;
      auto& [sum, weight] = beside[node];
      sum += w * kinetic(v, distal ? along.line(v).length : 0.0);
      weight += w;
    }
  }
  // Each 1D vessel's offsets (static = node's - offset) and forcing drops; its currents.
  struct Source {
    double offset_from = 0, offset_to = 0;
    std::vector<double> drops;  // G(x) along it
  };
  std::unordered_map<std::size_t, Source> source;
  std::vector<double> current(nodes, 0.0);
  for (std::size_t i = 0; i < held.size(); ++i) {
    const std::size_t v = held[i];
    if (!sourced[v]) continue;
    const VesselLine& line = along.line(v);
    const auto a = static_cast<std::size_t>(net.from[v]), b = static_cast<std::size_t>(net.to[v]);
    auto offset = [&](std::size_t node, double x) {
      if (!junction(node)) return 0.0;
      const auto other = beside.find(node);
      return kinetic(v, x) - (other != beside.end() ? other->second[0] / other->second[1] : 0.0);
    };
    Source& s = source[v];
    s.offset_from = offset(a, 0.0);
    s.offset_to = offset(b, line.length);
    pulse_of(v);
    s.drops = forcing_drops(line, slopes_of(v), rho, omega, at_from, at_to);
    // Flows out of a and b: Y (p_a, p_b + G) with p = X - offset; the part without X is a current.
    const TwoPort y = line.two_port(0.0);
    current[a] -= (-y.aa * s.offset_from + y.ab * (s.drops.back() - s.offset_to)).real();
    current[b] -= (-y.ba * s.offset_from + y.bb * (s.drops.back() - s.offset_to)).real();
  }
  // Each 0D vessel's own: its flow (1/l) int_{p_b}^{p_a} G dp, G = A^2 / (k mu(A)), has the
  // mean (1/l)(F(p_a) - F(p_b)) + (G'(p_a) <p_a1^2> - G'(p_b) <p_b1^2>) / (2 l): the second
  // part a current through it, from a to b.
  // Computed again where each vessel's shift is handed out: a per-vessel array would add
  // 8 B a vessel to the full tree's start.
  auto through = [&](std::size_t v) {
    auto capacity_slope = [&](std::size_t node) {  // G'(p) at the node's mean pressure
      const double area = laws[v].area(line_of.steady.node_pressure[node]), h = 1e-3 * area;
      auto capacity = [&](double x) { return flow_capacity(x, viscosity(x), k_friction); };
      return (capacity(area + h) - capacity(area - h)) / (2 * h) * laws[v].compliance_per_length(area);
    };
    const auto a = static_cast<std::size_t>(net.from[v]), b = static_cast<std::size_t>(net.to[v]);
    return (capacity_slope(a) * node_variance[a] - capacity_slope(b) * node_variance[b]) / (2 * net.length[v]);
  };
  in_blocks(held, threads, [&](std::size_t v) { return sourced[v] ? 0.0 : through(v); },
            [&](std::size_t v, double j) {
              if (sourced[v]) return;
              current[static_cast<std::size_t>(net.from[v])] -= j;
              current[static_cast<std::size_t>(net.to[v])] += j;
            });
  const std::vector<Complex>& x = solve_at_zero(std::move(current));
  auto line_at = [&](std::size_t v) { return (along.holds(v) ? along.line(v) : line_of(v)).two_port(0.0); };
  in_blocks(
      answered, threads,
      [&](std::size_t v) {  // an unforced vessel's: its line between its nodes' shifts, and its own current
        if (sourced[v]) return 0.0;
        const TwoPort y = line_at(v);
        const double pa = x[static_cast<std::size_t>(net.from[v])].real(), pb = x[static_cast<std::size_t>(net.to[v])].real();
        return (y.aa * pa + y.ab * pb).real() + through(v);
      },
      [&](std::size_t v, double dq) {
        const auto a = static_cast<std::size_t>(net.from[v]), b = static_cast<std::size_t>(net.to[v]);
        const auto found = sourced[v] ? source.find(v) : source.end();
        if (found == source.end()) {
          apply(v, dq, std::vector<double>{}, x[a].real(), x[b].real());
          return;
        }
        // A forced vessel: its line with its ends' offsets and its forcing's drop.
        const Source& f = found->second;
        const double pa = x[a].real() - f.offset_from, pb = x[b].real() - f.offset_to;
        const TwoPort y = line_at(v);
        dq = (y.aa * pa + y.ab * (pb + f.drops.back())).real();
        // The static mean's shift along it: the forced line's.
        apply(v, dq, mean_shift_profile(along.line(v), pa, dq, f.drops), x[a].real(), x[b].real());
      });
  for (std::size_t node = 0; node < nodes; ++node) node_pressure[node] += x[node].real();
}

// The plain solve at w = 0 with the mean shift's currents (the boundaries' waveforms held
// still): the whole system's.
struct WholeAtZero {
  const Network& net;
  const HarmonicNetwork& network;
  const RunBoundaries& boundaries;
  const std::vector<FourierSeries>& series;
  const LineAbout& line_of;
  HarmonicWorkspace& work;
  int threads;
  const std::vector<Complex>& operator()(std::vector<double>&& current) const {
    std::vector<FourierSeries> none = series;
    for (FourierSeries& f : none) std::fill(f.amplitude.begin(), f.amplitude.end(), Complex(0.0));
    solve_harmonic(net, network, boundaries, none, line_of, 0, 0.0, work, threads, current);
    std::vector<double>().swap(current);  // its 8 B a node gone before the vessels' shifts
    return work.current;
  }
};

}  // namespace

LinearPeriodic solve_linear_periodic(const Network& net, const Blood& blood, std::span<const TubeLaw> laws,
                                     const ViscosityTable& viscosity, const SteadyFlow& steady,
                                     const RunBoundaries& boundaries, int harmonics, int threads,
                                     const std::function<bool(const VesselLine&)>& shift_source) {
  if (harmonics < 1) throw std::invalid_argument("solve_linear_periodic: at least one harmonic");
  LinearPeriodic out = LinearPeriodic::about(net, blood, laws, viscosity, steady, threads);
  // Every harmonic kept: all of them at once, one to a thread. The system's structure and
  // the boundaries' series serve the mean shift too.
  const std::vector<FourierSeries> series = boundary_series(boundaries, harmonics);
  const HarmonicNetwork network = harmonic_network(net, boundaries);
  solve_harmonics(net, network, out, boundaries, series, harmonics, threads,
                  [&](int, std::vector<Complex>&& p) { out.node_pressure_.push_back(std::move(p)); });
  if (shift_source) {
    std::vector<bool> shift_sources(net.vessel_count());
    for (std::size_t v = 0; v < shift_sources.size(); ++v) shift_sources[v] = shift_source(out.line_[v]);
    const LineAbout line_of{net, laws, viscosity, steady, friction_coefficient(blood.alpha), blood.density};
    std::vector<double> node_shift(net.node_count(), 0.0);
    std::vector<double> variance(net.node_count(), 0.0);  // <p1^2> at each node
    const auto node_count = static_cast<std::int64_t>(variance.size());
    for (const std::vector<Complex>& p : out.node_pressure_) {
#pragma omp parallel for schedule(static) num_threads(threads) if (threads > 1)
      for (std::int64_t i = 0; i < node_count; ++i)
        variance[static_cast<std::size_t>(i)] += 0.5 * std::norm(p[static_cast<std::size_t>(i)]);
    }
    HarmonicWorkspace work;
    const VesselList every{nullptr, net.vessel_count()};
    solve_mean_shift(net, blood, laws, viscosity, boundaries, line_of, out, shift_sources, variance, node_shift, threads,
                     every, every, WholeAtZero{net, network, boundaries, series, line_of, work, threads},
                     [&](std::size_t v, double dq, std::vector<double>&& profile, double dx_from, double dx_to) {
                       out.mean_flow_[v] += dq;
                       if (!shift_sources[v]) return;  // its nodes' means move below, and it with them
                       // What lies beyond its nodes' shift, which moves their means below.
                       const double last = static_cast<double>(profile.size() - 1);
                       for (std::size_t i = 0; i < profile.size(); ++i) {
                         const double s = static_cast<double>(i) / last;
                         profile[i] -= (1 - s) * dx_from + s * dx_to;
                       }
                       out.mean_shift_[v] = std::move(profile);
                     });
    for (std::size_t node = 0; node < node_shift.size(); ++node) out.mean_node_pressure_[node] += node_shift[node];
  }
  return out;
}

LinearPeriodic solve_linear_periodic(const Network& net, const Blood& blood, std::span<const TubeLaw> laws,
                                     const ViscosityTable& viscosity, const SteadyFlow& steady,
                                     const RunBoundaries& boundaries, int harmonics, int threads,
                                     const std::function<bool(const VesselLine&)>& shift_source,
                                     const HarmonicShare& share) {
  if (harmonics < 1) throw std::invalid_argument("solve_linear_periodic: at least one harmonic");
  LinearPeriodic out;
  out.net_ = &net;
  out.period_ = driving_waveform(net).period;
  const LineAbout line_of{net, laws, viscosity, steady, friction_coefficient(blood.alpha), blood.density};
  // What it holds: its vessels and ghosts, and their ends, each at a place of its own.
  std::vector<std::int32_t> held;
  std::merge(share.vessels.begin(), share.vessels.end(), share.ghosts.begin(), share.ghosts.end(), std::back_inserter(held));
  out.kept_.assign(net.node_count(), -1);
  out.kept_vessel_.assign(net.vessel_count(), -1);
  std::vector<std::size_t> kept_node;
  auto keep_node = [&](std::int64_t node) {
    auto& slot = out.kept_[static_cast<std::size_t>(node)];
    if (slot >= 0) return;
    slot = static_cast<std::int32_t>(kept_node.size());
    kept_node.push_back(static_cast<std::size_t>(node));
    out.mean_node_pressure_.push_back(steady.node_pressure[static_cast<std::size_t>(node)]);
  };
  for (const std::int32_t vessel : held) {
    const auto v = static_cast<std::size_t>(vessel);
    out.kept_vessel_[v] = static_cast<std::int32_t>(out.mean_flow_.size());
    out.mean_flow_.push_back(steady.flow[v]);
    for (const std::int64_t node : {net.from[v], net.to[v]}) keep_node(node);
  }
  for (const std::int32_t node : share.nodes) keep_node(node);
  out.line_.resize(held.size());
  const auto held_count = static_cast<std::int64_t>(held.size());
#pragma omp parallel for schedule(static) num_threads(threads) if (threads > 1)
  for (std::int64_t i = 0; i < held_count; ++i)
    out.line_[static_cast<std::size_t>(i)] = line_of(static_cast<std::size_t>(held[static_cast<std::size_t>(i)]));
  const std::function<const VesselLine&(std::size_t)> line = [&](std::size_t v) -> const VesselLine& { return out.line(v); };
  // A line for the node terms: a vessel ending at a held pressure may be another share's.
  auto any_line = [&](std::size_t v) { return out.holds(v) ? out.line(v) : line_of(v); };
  const std::vector<FourierSeries> series = boundary_series(boundaries, harmonics);
  const HarmonicNetwork network = harmonic_network(net, boundaries);
  std::vector<Complex> shunt, current;
  auto solve = [&](double w) { share.solve(w, shunt, current, line); };
  for (int k = 1; k <= harmonics; ++k) {
    node_terms(net, network, boundaries, series, any_line, k, out.omega(k), shunt, current, {});
    solve(out.omega(k));
    std::vector<Complex> kept(kept_node.size());
    for (std::size_t j = 0; j < kept_node.size(); ++j) kept[j] = current[kept_node[j]];
    out.node_pressure_.push_back(std::move(kept));
  }
  if (!shift_source) return out;
  std::vector<bool> sourced(net.vessel_count(), false);
  share.on_every_share([&] {
    for (const std::int32_t v : held) sourced[static_cast<std::size_t>(v)] = shift_source(out.line(static_cast<std::size_t>(v)));
    for (const std::int32_t v : share.ghosts)
      if (sourced[static_cast<std::size_t>(v)])
        throw InputError("vessel " + std::to_string(net.id[static_cast<std::size_t>(v)]) +
                         " carries a wave across the ranks' cut: run the linear periodic state on fewer ranks");
  });
  std::vector<double> variance(net.node_count(), 0.0);  // <p1^2> at each node it holds, as the whole sums it
  for (const std::vector<Complex>& p : out.node_pressure_)
    for (std::size_t j = 0; j < kept_node.size(); ++j) variance[kept_node[j]] += 0.5 * std::norm(p[j]);
  std::vector<double> node_shift(net.node_count(), 0.0);
  auto at_zero = [&](std::vector<double>&& extra) -> const std::vector<Complex>& {
    std::vector<FourierSeries> none = series;
    for (FourierSeries& f : none) std::fill(f.amplitude.begin(), f.amplitude.end(), Complex(0.0));
    node_terms(net, network, boundaries, none, any_line, 0, 0.0, shunt, current, extra);
    std::vector<double>().swap(extra);
    solve(0.0);
    return current;
  };
  solve_mean_shift(net, blood, laws, viscosity, boundaries, line_of, out, sourced, variance, node_shift, threads,
                   VesselList{&held, 0}, VesselList{&share.vessels, 0}, at_zero,
                   [&](std::size_t v, double dq, std::vector<double>&& profile, double dx_from, double dx_to) {
                     out.mean_flow_[out.vessel_place(v)] += dq;
                     if (!sourced[v]) return;
                     const double last = static_cast<double>(profile.size() - 1);
                     for (std::size_t i = 0; i < profile.size(); ++i) {
                       const double s = static_cast<double>(i) / last;
                       profile[i] -= (1 - s) * dx_from + s * dx_to;
                     }
                     out.mean_shift_[v] = std::move(profile);
                   });
  for (std::size_t j = 0; j < kept_node.size(); ++j) out.mean_node_pressure_[j] += node_shift[kept_node[j]];
  return out;
}

PeriodicInstant solve_periodic_instant(const Network& net, const Blood& blood, std::span<const TubeLaw> laws,
                                       const ViscosityTable& viscosity, const SteadyFlow& steady,
                                       const RunBoundaries& boundaries, int harmonics, double time,
                                       const std::vector<bool>& keep, int threads, bool shift_mean) {
  if (harmonics < 1) throw std::invalid_argument("solve_periodic_instant: at least one harmonic");
  PeriodicInstant out{steady.node_pressure, steady.flow, LinearPeriodic{}};
  LinearPeriodic& along = out.along;
  along.net_ = &net;
  along.period_ = driving_waveform(net).period;
  // Every vessel's line is made again where a harmonic needs it (as LinearPeriodic::about
  // makes it: the same numbers), not held: 48 B a vessel at the run's start; `along` keeps
  // the kept vessels' and nodes' alone.
  const LineAbout line_of{net, laws, viscosity, steady, friction_coefficient(blood.alpha), blood.density};
  along.kept_.assign(net.node_count(), -1);
  along.kept_vessel_.assign(net.vessel_count(), -1);
  std::vector<std::size_t> kept_node;
  // The mean shift reads the pulse of the 0D vessels at the nodes where 1D ends meet them.
  std::vector<bool> held = keep;
  if (shift_mean) {
    std::vector<unsigned char> one_d_end(net.node_count(), 0);
    for (std::size_t v = 0; v < net.vessel_count(); ++v)
      if (keep[v]) one_d_end[static_cast<std::size_t>(net.from[v])] = one_d_end[static_cast<std::size_t>(net.to[v])] = 1;
    for (std::size_t v = 0; v < net.vessel_count(); ++v)
      if (one_d_end[static_cast<std::size_t>(net.from[v])] || one_d_end[static_cast<std::size_t>(net.to[v])]) held[v] = true;
  }
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    if (!held[v]) continue;
    along.kept_vessel_[v] = static_cast<std::int32_t>(along.line_.size());
    along.line_.push_back(line_of(v));
    along.mean_flow_.push_back(steady.flow[v]);
    for (const std::int64_t node : {net.from[v], net.to[v]}) {
      auto& slot = along.kept_[static_cast<std::size_t>(node)];
      if (slot >= 0) continue;
      slot = static_cast<std::int32_t>(kept_node.size());
      kept_node.push_back(static_cast<std::size_t>(node));
      along.mean_node_pressure_.push_back(steady.node_pressure[static_cast<std::size_t>(node)]);
    }
  }
  const auto nodes = static_cast<std::int64_t>(net.node_count()), vessels = static_cast<std::int64_t>(net.vessel_count());
  // One harmonic at a time, the threads within it, each added to every sum as it is solved,
  // in the order of k and the arithmetic of node_pressure_at and flow_at(v, 0.5, t). One
  // harmonic's system in memory, not one a thread (on the full tree with two threads, 0.4 GB
  // less at the run's start, then its largest moment).
  const std::vector<FourierSeries> series = boundary_series(boundaries, harmonics);
  const HarmonicNetwork network = harmonic_network(net, boundaries);
  HarmonicWorkspace work;
  std::vector<double> variance(shift_mean ? net.node_count() : 0, 0.0);  // <p1^2> at each node, for the shift
  for (int k = 1; k <= harmonics; ++k) {
    solve_harmonic(net, network, boundaries, series, line_of, k, along.omega(k), work, threads);
    const std::vector<Complex>& p = work.current;
    const Complex turn = std::polar(1.0, along.omega(k) * time);
#pragma omp parallel num_threads(threads) if (threads > 1)
    {
#pragma omp for schedule(static)
      for (std::int64_t i = 0; i < nodes; ++i) {
        out.node_pressure[static_cast<std::size_t>(i)] += (p[static_cast<std::size_t>(i)] * turn).real();
        if (shift_mean) variance[static_cast<std::size_t>(i)] += 0.5 * std::norm(p[static_cast<std::size_t>(i)]);
      }
#pragma omp for schedule(static)
      for (std::int64_t i = 0; i < vessels; ++i) {
        const auto v = static_cast<std::size_t>(i);
        const VesselLine line = line_of(v);
        const Complex q = line.flow(along.omega(k), p[static_cast<std::size_t>(net.from[v])],
                                    p[static_cast<std::size_t>(net.to[v])], 0.5 * line.length);
        out.middle_flow[v] += (q * turn).real();
      }
    }
    std::vector<Complex> kept(kept_node.size());
    for (std::size_t j = 0; j < kept_node.size(); ++j) kept[j] = p[kept_node[j]];
    along.node_pressure_.push_back(std::move(kept));
  }
  if (shift_mean)
    solve_mean_shift(net, blood, laws, viscosity, boundaries, line_of, along, keep, variance, out.node_pressure, threads,
                     VesselList{nullptr, net.vessel_count()}, VesselList{nullptr, net.vessel_count()},
                     WholeAtZero{net, network, boundaries, series, line_of, work, threads},
                     [&](std::size_t v, double dq, std::vector<double>&& profile, double dx_from, double dx_to) {
                       out.middle_flow[v] += dq;
                       if (!along.holds(v)) return;
                       if (profile.empty()) profile = {dx_from, dx_to};  // the kept 0D vessels: their nodes'
                       along.shift_mean(v, dq, std::move(profile));
                     });
  return out;
}

void LinearPeriodic::shift_mean(std::size_t vessel, double dq, std::vector<double>&& shift) {
  mean_flow_[vessel_place(vessel)] += dq;
  mean_shift_[vessel] = std::move(shift);
}

LinearPeriodic::Complex LinearPeriodic::pressure(int k, std::size_t vessel, double s) const {
  const VesselLine& line = line_[vessel_place(vessel)];
  return line.pressure(omega(k), node_pressure(k, static_cast<std::size_t>(net_->from[vessel])),
                       node_pressure(k, static_cast<std::size_t>(net_->to[vessel])), s * line.length);
}

LinearPeriodic::Complex LinearPeriodic::flow(int k, std::size_t vessel, double s) const {
  const VesselLine& line = line_[vessel_place(vessel)];
  return line.flow(omega(k), node_pressure(k, static_cast<std::size_t>(net_->from[vessel])),
                   node_pressure(k, static_cast<std::size_t>(net_->to[vessel])), s * line.length);
}

std::array<VesselLine::Point, 3> LinearPeriodic::ends_and_middle(int k, std::size_t vessel) const {
  return line_[vessel_place(vessel)].ends_and_middle(omega(k), node_pressure(k, static_cast<std::size_t>(net_->from[vessel])),
                                       node_pressure(k, static_cast<std::size_t>(net_->to[vessel])));
}

VesselLine::Point LinearPeriodic::middle(int k, std::size_t vessel) const {
  return line_[vessel_place(vessel)].middle(omega(k), node_pressure(k, static_cast<std::size_t>(net_->from[vessel])),
                                            node_pressure(k, static_cast<std::size_t>(net_->to[vessel])));
}

double LinearPeriodic::mean_pressure_at(std::size_t vessel, double s) const {
  double p = (1 - s) * mean_node_pressure_[node_place(static_cast<std::size_t>(net_->from[vessel]))] +
             s * mean_node_pressure_[node_place(static_cast<std::size_t>(net_->to[vessel]))];
  if (const auto shifted = mean_shift_.find(vessel); shifted != mean_shift_.end()) {
    const std::vector<double>& shift = shifted->second;
    const double at = std::clamp(s, 0.0, 1.0) * static_cast<double>(shift.size() - 1);
    const std::size_t i = std::min(static_cast<std::size_t>(at), shift.size() - 2);
    p += shift[i] + (at - static_cast<double>(i)) * (shift[i + 1] - shift[i]);
  }
  return p;
}

double LinearPeriodic::pressure_at(std::size_t vessel, double s, double t) const {
  double p = mean_pressure_at(vessel, s);
  for (int k = 1; k <= harmonics(); ++k) p += (pressure(k, vessel, s) * std::polar(1.0, omega(k) * t)).real();
  return p;
}

double LinearPeriodic::node_pressure_at(std::size_t node, double t) const {
  double p = mean_node_pressure_[node_place(node)];
  for (int k = 1; k <= harmonics(); ++k) p += (node_pressure(k, node) * std::polar(1.0, omega(k) * t)).real();
  return p;
}

double LinearPeriodic::flow_at(std::size_t vessel, double s, double t) const {
  double q = mean_flow_[vessel_place(vessel)];
  for (int k = 1; k <= harmonics(); ++k) q += (flow(k, vessel, s) * std::polar(1.0, omega(k) * t)).real();
  return q;
}

}  // namespace hemotree
