// The periodic state of a network linearised about its loaded steady state, harmonic by
// harmonic: the mean is the steady flow of the pulse solver's own equations (every vessel at
// the lumen of its mean pressure), and each harmonic k of the inflow (w_k = 2 pi k / T)
// drives the network's small oscillations about it:
//   - each vessel a uniform transmission line about its loaded lumen (harmonic/vessel_line.hpp;
//     where the pulse crosses it in phase, the 0D vessel's R, L and C),
//   - each outlet its impedance Z(w) to an outflow pressure that does not oscillate
//     (boundaries/: R; RCR: R1 + R2 / (1 + i w R2 C)),
//   - a prescribed flow a current of its waveform's k-th harmonic into its node, a prescribed
//     pressure its node held at its waveform's k-th harmonic,
// in one complex nodal system per harmonic (network_flow/harmonic_system.hpp): on a tree, the
// elimination from the leaves, O(vessels) per harmonic.
//
// It leaves out what is nonlinear in the 1D model: the convective term, the tube law's
// curvature over the pulse (the lumen's swing is a few per cent in arteries), and the
// friction's dependence on the lumen; their effect on the time-stepped periodic state is of
// the order of the square of the pulse's relative amplitude (tests/test_linear_periodic.cpp).
#pragma once

#include <array>
#include <complex>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <numbers>
#include <span>
#include <unordered_map>
#include <vector>

#include "harmonic/fourier_series.hpp"
#include "harmonic/vessel_line.hpp"
#include "formats/network.hpp"
#include "formats/run_boundaries.hpp"
#include "physics/blood.hpp"
#include "physics/tube_law.hpp"
#include "physics/viscosity_table.hpp"
#include "steady/steady_flow.hpp"

namespace hemotree {

struct PeriodicInstant;
struct HarmonicShare;

class LinearPeriodic {
 public:
  using Complex = std::complex<double>;

  double period() const { return period_; }
  int harmonics() const { return static_cast<int>(node_pressure_.size()); }
  double omega(int k) const { return 2 * std::numbers::pi * k / period_; }
  // A vessel's line, one the solve kept (every one, or those of solve_periodic_instant's `keep`).
  const VesselLine& line(std::size_t vessel) const { return line_[vessel_place(vessel)]; }
  bool holds(std::size_t vessel) const { return kept_vessel_.empty() || kept_vessel_[vessel] >= 0; }
  // Moves a kept vessel's mean by the periodic state's second-order shift (harmonic/mean_shift.hpp):
  // its flow by dq, its pressure by `shift`, sampled evenly from its start to its end (at least
  // two samples; linear between them).
  void shift_mean(std::size_t vessel, double dq, std::vector<double>&& shift);
  // The loaded (mean) state: per node [Pa], per vessel [m^3/s, from -> to] (a whole
  // solution's; an instant's and a share's keep their kept nodes and vessels only, by their
  // places: read those by node and vessel below).
  const std::vector<double>& mean_node_pressure() const { return mean_node_pressure_; }
  const std::vector<double>& mean_flow() const { return mean_flow_; }
  // The same of one node, one vessel (one the solve kept).
  double mean_node_pressure(std::size_t node) const { return mean_node_pressure_[node_place(node)]; }
  double mean_flow(std::size_t vessel) const { return mean_flow_[vessel_place(vessel)]; }
  // Harmonic k >= 1 at a node, and in a vessel at a fraction s of its length from `from`
  // (one the solve kept).
  Complex node_pressure(int k, std::size_t node) const {
    return node_pressure_[static_cast<std::size_t>(k - 1)][node_place(node)];
  }
  Complex pressure(int k, std::size_t vessel, double s) const;
  Complex flow(int k, std::size_t vessel, double s) const;
  // Harmonic k >= 1 at the vessel's start, middle and end; at its middle alone.
  std::array<VesselLine::Point, 3> ends_and_middle(int k, std::size_t vessel) const;
  VesselLine::Point middle(int k, std::size_t vessel) const;
  // The periodic state at time t: the mean plus every harmonic. The mean pressure along a
  // vessel is taken linear between its nodes, plus its second-order shift where one was kept.
  double pressure_at(std::size_t vessel, double s, double t) const;
  double mean_pressure_at(std::size_t vessel, double s) const;  // the mean alone
  double node_pressure_at(std::size_t node, double t) const;
  double flow_at(std::size_t vessel, double s, double t) const;

  friend LinearPeriodic solve_linear_periodic(const Network&, const Blood&, std::span<const TubeLaw>,
                                              const ViscosityTable&, const SteadyFlow&,
                                              const RunBoundaries&, int, int,
                                              const std::function<bool(const VesselLine&)>&);
  friend LinearPeriodic solve_linear_periodic(const Network&, const Blood&, std::span<const TubeLaw>,
                                              const ViscosityTable&, const SteadyFlow&,
                                              const RunBoundaries&, int, int,
                                              const std::function<bool(const VesselLine&)>&, const HarmonicShare&);
  friend PeriodicInstant solve_periodic_instant(const Network&, const Blood&, std::span<const TubeLaw>,
                                                const ViscosityTable&, const SteadyFlow&,
                                                const RunBoundaries&, int, double,
                                                const std::vector<bool>&, int, bool);
  friend PeriodicInstant solve_periodic_instant(const Network&, const Blood&, std::span<const TubeLaw>,
                                                const ViscosityTable&, const SteadyFlow&,
                                                const RunBoundaries&, int, double,
                                                const std::vector<bool>&, int, bool, const HarmonicShare&);

 private:
  // The mean state and every vessel's line about it; no harmonic yet.
  static LinearPeriodic about(const Network& net, const Blood& blood, std::span<const TubeLaw> laws,
                              const ViscosityTable& viscosity, const SteadyFlow& steady, int threads);
  const Network* net_ = nullptr;
  double period_ = 1.0;
  // Per node, or per kept node at its place in kept_: the mean pressure and each harmonic's.
  std::vector<double> mean_node_pressure_;
  std::vector<std::vector<Complex>> node_pressure_;  // [k - 1][place]
  // Per vessel, or per kept vessel at its place in kept_vessel_: the mean flow and the line.
  std::vector<double> mean_flow_;
  std::vector<VesselLine> line_;
  std::vector<std::int32_t> kept_, kept_vessel_;  // per node, per vessel: its place, -1 (empty: its own)
  // Per vessel so moved, the mean pressure's second-order shift along it beyond its nodes' means.
  std::unordered_map<std::size_t, std::vector<double>> mean_shift_;
  // Keeps vessel v at the next place (its mean flow from `steady`; the caller adds its line at
  // the same place) and its nodes (their mean pressures) where they are not kept yet;
  // kept_node lists the kept nodes by place. kept_ and kept_vessel_ sized first.
  void keep_vessel(std::size_t v, const SteadyFlow& steady, std::vector<std::size_t>& kept_node);
  void keep_node(std::size_t node, const SteadyFlow& steady, std::vector<std::size_t>& kept_node);
  std::size_t node_place(std::size_t node) const { return kept_.empty() ? node : static_cast<std::size_t>(kept_[node]); }
  std::size_t vessel_place(std::size_t v) const { return kept_vessel_.empty() ? v : static_cast<std::size_t>(kept_vessel_[v]); }
};

// The linear periodic state with the first `harmonics` harmonics of the network's boundary
// waveforms (their common period: driving_waveform). laws: per vessel (a tapered vessel's at
// its proximal end); viscosity: mu(A) of the run's blood. Throws InputError where the steady
// state does (a reflection outlet has no steady state), or where a part of the network has
// no path to ground. threads: the harmonics one to a thread, and the vessels' lines (the
// same numbers for any count).
LinearPeriodic solve_linear_periodic(const Network& net, const Blood& blood, std::span<const TubeLaw> laws,
                                     const ViscosityTable& viscosity, int harmonics, int threads = 1,
                                     const std::function<bool(const VesselLine&)>& shift_source = {});
// The same about a steady state already solved (solve_distended_steady_flow with the same
// blood, laws and viscosity), with the network's boundary list (formats/run_boundaries.hpp) where the caller
// holds it.
// shift_source: where given, the mean moves by its second-order shift
// (harmonic/mean_shift.hpp) with the forcing of the vessels whose line it marks (the run's 1D ones).
LinearPeriodic solve_linear_periodic(const Network& net, const Blood& blood, std::span<const TubeLaw> laws,
                                     const ViscosityTable& viscosity, const SteadyFlow& steady,
                                     const RunBoundaries& boundaries, int harmonics, int threads = 1,
                                     const std::function<bool(const VesselLine&)>& shift_source = {});

// Vessel v's line about a distended steady state (the one solve_linear_periodic takes it about):
// its R', L', C' at the lumen of its mean pressure, its length, mean velocity and profile.
VesselLine loaded_line(const Network& net, const Blood& blood, std::span<const TubeLaw> laws,
                       const ViscosityTable& viscosity, const SteadyFlow& steady, std::size_t v);

// A share of the network whose linear periodic state this process solves with others, each
// harmonic's nodal system over them all (distributed/linear_periodic_over_ranks.hpp).
struct HarmonicShare {
  // Its vessels, increasing: those it answers for (their lines, amplitudes and shifts).
  std::vector<std::int32_t> vessels;
  // Vessels it does not answer for but whose terms it sums at its nodes, increasing (a
  // distributed top's edges into the shares): with them every vessel at a node it holds is
  // its own or a ghost, so every sum at such a node runs over the whole network's terms.
  std::vector<std::int32_t> ghosts;
  // Its nodes, whose amplitudes and mean it answers for: with the ends of its vessels and
  // ghosts, those it keeps (a node no vessel reaches is one of some share's).
  std::vector<std::int32_t> nodes;
  // One harmonic's nodal system at angular frequency w, solved with every other share:
  // per node of the network its shunt and current (this share's nodes' entries as the whole
  // system's), each of its vessels' two-port at w (two_port(v)); the amplitudes at its nodes
  // and at the ends of its vessels and ghosts into current. A part with no path to ground:
  // InputError, as the one-process solve says it.
  std::function<void(double w, std::span<const Complex> shunt, std::span<Complex> current,
                     const std::function<TwoPort(std::size_t)>& two_port)>
      solve;
  // Runs a step that may fail on one share alone so that its failure is every share's
  // (mpi/session.hpp's on_every_rank).
  std::function<void(const std::function<void()>&)> on_every_share;
  // Whether its ghosts are every vessel it does not answer for (a share holding the whole
  // network's lines): then a ghost that is a shift source has its ends' neighbours too, and is
  // taken, not refused.
  bool holds_every_vessel = false;
};

// The linear periodic state of a share: the lines, amplitudes, mean and shift of its vessels
// and ghosts (those it holds: `holds`), each the bits of the one-process solve. steady: the
// distended state's pressures at the ends of its vessels and ghosts and their flows. Every
// share calls it alike. A ghost that is a shift source (a 1D vessel across a cut) is refused
// on every share (InputError), unless the share holds every vessel.
LinearPeriodic solve_linear_periodic(const Network& net, const Blood& blood, std::span<const TubeLaw> laws,
                                     const ViscosityTable& viscosity, const SteadyFlow& steady,
                                     const RunBoundaries& boundaries, int harmonics, int threads,
                                     const std::function<bool(const VesselLine&)>& shift_source,
                                     const HarmonicShare& share);

// The linear periodic state at one instant t: every node's pressure and every vessel's flow
// at its middle, summed harmonic by harmonic as each is solved, and the whole state (`along`)
// for the vessels marked in `keep` only (the amplitudes at their nodes): what a time-stepped
// run starts from (pulse/pulse_solver.cpp), without every node's K amplitudes at once (16 B a
// node and harmonic: 0.6 GB for ten on the full tree). The same numbers, bit for bit, as
// LinearPeriodic's node_pressure_at(i, t) and flow_at(v, 0.5, t). shift_mean: about the mean
// moved by its second-order shift (harmonic/mean_shift.hpp), forced in the vessels of `keep`
// (`along` then holds the 0D vessels beside their ends too).
struct PeriodicInstant {
  std::vector<double> node_pressure, middle_flow;  // per node [Pa], per vessel [m^3/s]
  LinearPeriodic along;
};
PeriodicInstant solve_periodic_instant(const Network& net, const Blood& blood, std::span<const TubeLaw> laws,
                                       const ViscosityTable& viscosity, const SteadyFlow& steady,
                                       const RunBoundaries& boundaries, int harmonics, double time,
                                       const std::vector<bool>& keep, int threads = 1, bool shift_mean = false);
// The same over a share (HarmonicShare): node_pressure and middle_flow hold the share's nodes'
// and vessels' numbers (the other entries unspecified), `along` the kept vessels it holds,
// each the bits of the one-process instant. A kept vessel must be none of its ghosts (the 1D
// vessels are kept on the top): InputError on every share otherwise.
PeriodicInstant solve_periodic_instant(const Network& net, const Blood& blood, std::span<const TubeLaw> laws,
                                       const ViscosityTable& viscosity, const SteadyFlow& steady,
                                       const RunBoundaries& boundaries, int harmonics, double time,
                                       const std::vector<bool>& keep, int threads, bool shift_mean,
                                       const HarmonicShare& share);

}  // namespace hemotree
