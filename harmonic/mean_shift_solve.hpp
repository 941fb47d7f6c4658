// The mean's second-order shift solved over a network (the model: harmonic/mean_shift.hpp;
// internal to harmonic/): the sources of the 1D vessels and the junctions' kinetic pressures,
// the 0D vessels' own currents, one nodal system at w = 0, each vessel's shift, over every
// vessel or over a share's (harmonic/linear_periodic.hpp's HarmonicShare).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <unordered_map>
#include <utility>
#include <vector>

#include "harmonic/harmonic_rows.hpp"
#include "harmonic/linear_periodic.hpp"
#include "harmonic/mean_shift.hpp"

namespace hemotree {

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
inline LumenSlopes lumen_slopes(const TubeLaw& law, const ViscosityTable& viscosity, double k_friction, double area) {
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

// The same over a share of the network (HarmonicShare): its rows' node terms, its solve with
// the other shares, in its own arrays (shunt and current, every node's, kept by the caller).
struct ShareAtZero {
  const Network& net;
  const HarmonicNetwork& network;
  const RunBoundaries& boundaries;
  const std::vector<FourierSeries>& series;
  const LineAbout& line_of;
  const HarmonicShare& share;
  const NodeSubset& subset;  // the share's nodes
  std::vector<Complex>&shunt, &current;
  const std::vector<Complex>& operator()(std::vector<double>&& extra) const {
    std::vector<FourierSeries> none = series;
    for (FourierSeries& f : none) std::fill(f.amplitude.begin(), f.amplitude.end(), Complex(0.0));
    node_terms(net, network, boundaries, none, line_of, 0, 0.0, shunt, current, extra, &subset);
    std::vector<double>().swap(extra);
    share.solve(0.0, shunt, current, [&](std::size_t v) { return line_of(v).two_port(0.0); });
    return current;
  }
};

}  // namespace hemotree
