// Small networks built in code for the solver tests, with the tube law given directly
// (net.beta) and Newtonian blood, so that every coefficient of the model is known exactly.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <numbers>

#include "formats/network.hpp"

namespace hemotree::test_networks {

constexpr double rho = 1050.0;

inline Blood newtonian(double viscosity) {
  Blood b;
  b.density = rho;
  b.rheology = Rheology::newtonian;
  b.newtonian_viscosity = viscosity;
  b.alpha = 4.0 / 3.0;
  return b;
}

// beta that gives wave speed c at the reference area: c^2 = beta sqrt(A) / (2 rho).
inline double beta_for_wave_speed(double c, double area) { return 2 * rho * c * c / std::sqrt(area); }

// A chain of `count` equal vessels (ids 0..count-1) from node 0 to node count along x, with
// the tube law given directly. Wall data are present too but unused (beta wins).
inline Network chain(int count, double total_length, double diameter, double beta, double reference_pressure,
                     const Blood& blood) {
  Network net;
  for (int k = 0; k <= count; ++k) net.add_node(k);
  for (int k = 0; k < count; ++k)
    net.add_vessel(k, k, k + 1, total_length / count, diameter, 0.1 * diameter, 1e6, k);
  net.beta.assign(static_cast<std::size_t>(count), beta);
  net.reference_pressure.assign(static_cast<std::size_t>(count), reference_pressure);
  net.blood = blood;
  return net;
}

// A waveform tabulated from f on [0, duration] with `samples` points, and zero (the table
// wraps linearly from the last sample to the first) until the period ends. Dense samples
// make the linear interpolation error negligible: (dt_sample / sigma)^2 / 8 relative for a
// Gaussian of width sigma.
inline Waveform tabulate(const std::function<double(double)>& f, double duration, int samples, double period) {
  Waveform w;
  w.shape = Waveform::Shape::table;
  w.period = period;
  for (int k = 0; k < samples; ++k) {
    const double t = duration * k / (samples - 1);
    w.time.push_back(t);
    w.value.push_back(f(t));
  }
  return w;
}

// root 0 -> 1, daughters 1 -> 2 and 1 -> 3 (1 cm, 0.1 mm), node ids first_id to first_id + 3;
// no boundary conditions.
inline Network bifurcation(std::int64_t first_id = 0) {
  Network net;
  for (int n = 0; n < 4; ++n) net.add_node(first_id + n);
  net.add_vessel(0, 0, 1, 0.01, 1e-4, 1e-5, 2e5, 0);
  net.add_vessel(1, 1, 2, 0.01, 1e-4, 1e-5, 2e5, 1);
  net.add_vessel(2, 1, 3, 0.01, 1e-4, 1e-5, 2e5, 1);
  return net;
}

inline Outlet reflection_outlet(std::int32_t vessel, double coefficient) {
  Outlet o;
  o.vessel = vessel;
  o.type = BoundaryType::reflection;
  o.reflection = coefficient;
  return o;
}

inline Outlet resistance_outlet(std::int32_t vessel, double r, double p_out) {
  Outlet o;
  o.vessel = vessel;
  o.type = BoundaryType::resistance;
  o.r = r;
  o.p_out = p_out;
  return o;
}

inline Outlet rcr_outlet(std::int32_t vessel, double r1, double c, double r2, double p_out) {
  Outlet o;
  o.vessel = vessel;
  o.type = BoundaryType::rcr;
  o.r1 = r1;
  o.c = c;
  o.r2 = r2;
  o.p_out = p_out;
  return o;
}

// Boundary conditions at nodes (format version 2).
inline NodeBoundary flow_boundary(std::int32_t node, const Waveform& w) {
  NodeBoundary b;
  b.node = node;
  b.type = BoundaryType::flow;
  b.waveform = w;
  return b;
}

inline NodeBoundary flow_boundary(std::int32_t node, double q) { return flow_boundary(node, Waveform::constant_value(q)); }

inline NodeBoundary pressure_boundary(std::int32_t node, double p) {
  NodeBoundary b;
  b.node = node;
  b.type = BoundaryType::pressure;
  b.waveform = Waveform::constant_value(p);
  return b;
}

inline NodeBoundary outlet_boundary(std::int32_t node, const Outlet& o) {
  NodeBoundary b;
  b.node = node;
  b.type = o.type;
  b.outlet = o;
  return b;
}

}  // namespace hemotree::test_networks
