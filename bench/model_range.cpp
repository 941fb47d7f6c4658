// Where each vessel model is right (issue 12, point 5): one vessel between a pulsatile inflow
// and a resistance outlet, solved 1D (DG) and 0D (lumped), over a range of lengths, for a
// large artery (5 mm, c0 = 5 m/s: waves) and a capillary (6 um, Pries blood: diffusion).
// For each length: the criterion's two numbers (transit L / c0 over the period, w R C at the
// fundamental) and the largest difference of the 0D pressure from the 1D one at the inlet
// and at the vessel's centre over the second cycle, relative to the 1D pulse's amplitude.
//
// usage: bench/model_range        (figures: bench/README.md, docs/solver.md §10)
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "physics/poiseuille.hpp"
#include "pulse/pulse_solver.hpp"

using namespace hemotree;

namespace {

constexpr double pi = std::numbers::pi;

// The paper's half-sine pulse, period 1 s.
Network vessel(double length, double diameter, double wave_speed, const Blood& blood, double mean_flow) {
  Network net;
  net.add_node(0);
  net.add_node(1);
  net.add_vessel(0, 0, 1, length, diameter, 0.1 * diameter, 1e6, 0);
  const double area = pi / 4 * diameter * diameter;
  net.beta.assign(1, 2 * blood.density * wave_speed * wave_speed / std::sqrt(area));
  net.reference_pressure.assign(1, 4000);
  net.blood = blood;
  Waveform w;
  w.period = 1;
  w.mean = mean_flow;
  w.systole = 0.3;
  net.inlet = Inlet{0, w};
  // An outlet of the vessel's characteristic impedance, plus a resistance that sets ~40 mmHg.
  Outlet o;
  o.vessel = 0;
  o.type = BoundaryType::resistance;
  o.r = blood.density * wave_speed / area + 1000 / mean_flow;
  o.p_out = 1000;
  net.outlets.push_back(o);
  return net;
}

// Pressure at x = 0 and 0.5 after every step of the second cycle.
std::vector<std::array<double, 2>> second_cycle(const Network& net, ModelChoice model, double& dt) {
  SolverOptions options;
  options.model = model;
  options.start = StartChoice::steady;
  PulseSolver solver(net, options);
  const auto steps = static_cast<std::size_t>(std::ceil(1.0 / solver.dt() - 1e-9));
  solver.set_time_step(1.0 / static_cast<double>(steps));
  dt = solver.dt();
  std::vector<std::array<double, 2>> p;
  for (std::size_t k = 0; k < 2 * steps; ++k) {
    solver.step();
    if (k >= steps) p.push_back({solver.pressure_at(0, 0), solver.pressure_at(0, 0.5)});
  }
  return p;
}

double at(const std::vector<std::array<double, 2>>& p, double dt, double t, int which) {
  const double s = t / dt - 1;
  const auto k = std::clamp<std::ptrdiff_t>(static_cast<std::ptrdiff_t>(std::floor(s)), 0, static_cast<std::ptrdiff_t>(p.size()) - 2);
  const double w = std::clamp(s - static_cast<double>(k), 0.0, 1.0);
  return p[static_cast<std::size_t>(k)][which] * (1 - w) + p[static_cast<std::size_t>(k) + 1][which] * w;
}

void sweep(const char* name, double diameter, double wave_speed, const Blood& blood, double mean_flow,
           const std::vector<double>& lengths) {
  std::printf("\n%s (D = %.3g um, c0 = %.3g m/s)\n", name, diameter * 1e6, wave_speed);
  std::printf("%10s %12s %10s %14s %14s\n", "L [mm]", "transit/T", "w R C", "error at inlet", "error at centre");
  for (const double length : lengths) {
    const Network net = vessel(length, diameter, wave_speed, blood, mean_flow);
    double dt1 = 0, dt0 = 0;
    std::vector<std::array<double, 2>> one, zero;
    try {
      one = second_cycle(net, ModelChoice::one_d, dt1);
      zero = second_cycle(net, ModelChoice::zero_d, dt0);
    } catch (const std::exception& e) {
      std::printf("%10.3g: %s\n", length * 1e3, e.what());
      continue;
    }
    const ViscosityTable mu(blood);
    const double area = pi / 4 * diameter * diameter, beta = net.beta[0];
    const double c = length * 2 * std::sqrt(area) / beta;
    const double r = friction_coefficient(blood.alpha) * mu(area) * length / (area * area);
    double error[2] = {0, 0};
    for (int which = 0; which < 2; ++which) {
      double low = INFINITY, high = -INFINITY;
      for (const auto& p : one) low = std::min(low, p[which]), high = std::max(high, p[which]);
      for (std::size_t k = 0; k < zero.size(); ++k) {
        const double t = static_cast<double>(k + 1) * dt0;
        error[which] = std::max(error[which], std::abs(zero[k][which] - at(one, dt1, t, which)) / (high - low));
      }
    }
    std::fflush(stdout);
    std::printf("%10.3g %12.3g %10.3g %13.2f%% %13.2f%%\n", length * 1e3, length / wave_speed, 2 * pi * r * c,
                100 * error[0], 100 * error[1]);
  }
}

}  // namespace

int main() {
  Blood newtonian;
  newtonian.rheology = Rheology::newtonian;
  newtonian.newtonian_viscosity = 3.5e-3;
  sweep("large artery", 5e-3, 5.0, newtonian, 5e-6, {1e-3, 3e-3, 1e-2, 3e-2, 0.1, 0.3});
  Blood pries;  // the defaults: Pries in vivo, hematocrit 0.45
  sweep("capillary", 6e-6, 3.0, pries, 5e-15, {1e-4, 3e-4, 1e-3});
  return 0;
}
