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

#include "core/errors.hpp"
#include "harmonic/harmonic_rows.hpp"
#include "harmonic/mean_shift_solve.hpp"
#include "network_flow/harmonic_system.hpp"
#include "physics/poiseuille.hpp"

namespace hemotree {

namespace {

// The kept vessels and every vessel that meets one at a node: the mean shift reads the pulse
// of the 0D vessels at the nodes where 1D ends meet them.
std::vector<bool> with_neighbours(const Network& net, const std::vector<bool>& keep) {
  std::vector<unsigned char> end(net.node_count(), 0);
  for (std::size_t v = 0; v < net.vessel_count(); ++v)
    if (keep[v]) end[static_cast<std::size_t>(net.from[v])] = end[static_cast<std::size_t>(net.to[v])] = 1;
  std::vector<bool> out = keep;
  for (std::size_t v = 0; v < net.vessel_count(); ++v)
    if (end[static_cast<std::size_t>(net.from[v])] || end[static_cast<std::size_t>(net.to[v])]) out[v] = true;
  return out;
}

// What an instant takes of each vessel's mean shift: its middle flow's, and a kept vessel's
// along it (a kept 0D vessel's: its nodes').
auto shift_into(PeriodicInstant& out) {
  return [&out](std::size_t v, double dq, std::vector<double>&& profile, double dx_from, double dx_to) {
    out.middle_flow[v] += dq;
    if (!out.along.holds(v)) return;
    if (profile.empty()) profile = {dx_from, dx_to};
    out.along.shift_mean(v, dq, std::move(profile));
  };
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
  for (const std::int32_t v : held) out.keep_vessel(static_cast<std::size_t>(v), steady, kept_node);
  for (const std::int32_t node : share.nodes) out.keep_node(static_cast<std::size_t>(node), steady, kept_node);
  out.line_.resize(held.size());
  const auto held_count = static_cast<std::int64_t>(held.size());
#pragma omp parallel for schedule(static) num_threads(threads) if (threads > 1)
  for (std::int64_t i = 0; i < held_count; ++i)
    out.line_[static_cast<std::size_t>(i)] = line_of(static_cast<std::size_t>(held[static_cast<std::size_t>(i)]));
  const std::vector<FourierSeries> series = boundary_series(boundaries, harmonics);
  const HarmonicNetwork network = harmonic_network(net, boundaries);
  const NodeSubset subset(boundaries, share.nodes, net.node_count());  // the rows its solve reads
  std::vector<Complex> shunt, current;
  auto solve = [&](double w) { share.solve(w, shunt, current, [&](std::size_t v) { return out.line(v).two_port(w); }); };
  for (int k = 1; k <= harmonics; ++k) {
    node_terms(net, network, boundaries, series, line_of, k, out.omega(k), shunt, current, {}, &subset);
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
      if (sourced[static_cast<std::size_t>(v)] && !share.holds_every_vessel)
        throw InputError("vessel " + std::to_string(net.id[static_cast<std::size_t>(v)]) +
                         " carries a wave across the ranks' cut: run the linear periodic state on fewer ranks");
  });
  std::vector<double> variance(net.node_count(), 0.0);  // <p1^2> at each node it holds, as the whole sums it
  for (const std::vector<Complex>& p : out.node_pressure_)
    for (std::size_t j = 0; j < kept_node.size(); ++j) variance[kept_node[j]] += 0.5 * std::norm(p[j]);
  std::vector<double> node_shift(net.node_count(), 0.0);
  solve_mean_shift(net, blood, laws, viscosity, boundaries, line_of, out, sourced, variance, node_shift, threads,
                   VesselList{&held, 0}, VesselList{&share.vessels, 0},
                   ShareAtZero{net, network, boundaries, series, line_of, share, subset, shunt, current},
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
  const std::vector<bool> held = shift_mean ? with_neighbours(net, keep) : keep;
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    if (!held[v]) continue;
    along.keep_vessel(v, steady, kept_node);
    along.line_.push_back(line_of(v));
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
                     shift_into(out));
  return out;
}

PeriodicInstant solve_periodic_instant(const Network& net, const Blood& blood, std::span<const TubeLaw> laws,
                                       const ViscosityTable& viscosity, const SteadyFlow& steady,
                                       const RunBoundaries& boundaries, int harmonics, double time,
                                       const std::vector<bool>& keep, int threads, bool shift_mean,
                                       const HarmonicShare& share) {
  if (harmonics < 1) throw std::invalid_argument("solve_periodic_instant: at least one harmonic");
  share.on_every_share([&] {
    for (const std::int32_t v : share.ghosts)
      if (keep[static_cast<std::size_t>(v)])
        throw InputError("vessel " + std::to_string(net.id[static_cast<std::size_t>(v)]) +
                         " carries a wave across the ranks' cut: run the periodic start on fewer ranks");
  });
  PeriodicInstant out{steady.node_pressure, steady.flow, LinearPeriodic{}};
  LinearPeriodic& along = out.along;
  along.net_ = &net;
  along.period_ = driving_waveform(net).period;
  const LineAbout line_of{net, laws, viscosity, steady, friction_coefficient(blood.alpha), blood.density};
  std::vector<std::int32_t> held;  // its vessels and ghosts
  std::merge(share.vessels.begin(), share.vessels.end(), share.ghosts.begin(), share.ghosts.end(), std::back_inserter(held));
  // What `along` keeps, as the one-process instant keeps it, of the vessels this share holds.
  const std::vector<bool> kept_vessel = shift_mean ? with_neighbours(net, keep) : keep;
  along.kept_.assign(net.node_count(), -1);
  along.kept_vessel_.assign(net.vessel_count(), -1);
  std::vector<std::size_t> kept_node;
  for (const std::int32_t vessel : held) {
    const auto v = static_cast<std::size_t>(vessel);
    if (!kept_vessel[v]) continue;
    along.keep_vessel(v, steady, kept_node);
    along.line_.push_back(line_of(v));
  }
  // The nodes whose sums it keeps: its own and the ends of its vessels and ghosts (the shift's
  // variances there), each summed over the harmonics in their order as the whole sums it.
  std::vector<std::int32_t> summed(share.nodes.begin(), share.nodes.end());
  for (const std::int32_t v : held)
    summed.insert(summed.end(), {static_cast<std::int32_t>(net.from[static_cast<std::size_t>(v)]),
                                 static_cast<std::int32_t>(net.to[static_cast<std::size_t>(v)])});
  std::sort(summed.begin(), summed.end());
  summed.erase(std::unique(summed.begin(), summed.end()), summed.end());
  const std::vector<FourierSeries> series = boundary_series(boundaries, harmonics);
  const HarmonicNetwork network = harmonic_network(net, boundaries);
  const NodeSubset subset(boundaries, share.nodes, net.node_count());  // the rows its solve reads
  std::vector<Complex> shunt, current;
  std::vector<double> variance(shift_mean ? net.node_count() : 0, 0.0);
  for (int k = 1; k <= harmonics; ++k) {
    const double w = along.omega(k);
    node_terms(net, network, boundaries, series, line_of, k, w, shunt, current, {}, &subset);
    share.solve(w, shunt, current, [&](std::size_t v) { return line_of(v).two_port(w); });
    const Complex turn = std::polar(1.0, w * time);
    for (const std::int32_t node : summed) {
      const auto i = static_cast<std::size_t>(node);
      out.node_pressure[i] += (current[i] * turn).real();
      if (shift_mean) variance[i] += 0.5 * std::norm(current[i]);
    }
    const auto own = static_cast<std::int64_t>(share.vessels.size());
#pragma omp parallel for schedule(static) num_threads(threads) if (threads > 1)
    for (std::int64_t i = 0; i < own; ++i) {
      const auto v = static_cast<std::size_t>(share.vessels[static_cast<std::size_t>(i)]);
      const VesselLine line = line_of(v);
      const Complex q = line.flow(w, current[static_cast<std::size_t>(net.from[v])], current[static_cast<std::size_t>(net.to[v])],
                                  0.5 * line.length);
      out.middle_flow[v] += (q * turn).real();
    }
    std::vector<Complex> kept(kept_node.size());
    for (std::size_t j = 0; j < kept_node.size(); ++j) kept[j] = current[kept_node[j]];
    along.node_pressure_.push_back(std::move(kept));
  }
  if (!shift_mean) return out;
  solve_mean_shift(net, blood, laws, viscosity, boundaries, line_of, along, keep, variance, out.node_pressure, threads,
                   VesselList{&held, 0}, VesselList{&share.vessels, 0},
                   ShareAtZero{net, network, boundaries, series, line_of, share, subset, shunt, current},
                   shift_into(out));
  return out;
}

void LinearPeriodic::keep_node(std::size_t node, const SteadyFlow& steady, std::vector<std::size_t>& kept_node) {
  auto& slot = kept_[node];
  if (slot >= 0) return;
  slot = static_cast<std::int32_t>(kept_node.size());
  kept_node.push_back(node);
  mean_node_pressure_.push_back(steady.node_pressure[node]);
}

void LinearPeriodic::keep_vessel(std::size_t v, const SteadyFlow& steady, std::vector<std::size_t>& kept_node) {
  kept_vessel_[v] = static_cast<std::int32_t>(mean_flow_.size());
  mean_flow_.push_back(steady.flow[v]);
  for (const std::int64_t node : {net_->from[v], net_->to[v]}) keep_node(static_cast<std::size_t>(node), steady, kept_node);
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
