// Validation on a measured network (docs/validation.md): the rat mesentery of Pries et al.
// (Secomb's network.dat, 1130 segments, 159 loops, 36 boundary nodes) in steady flow with the
// Pries in vivo law at a constant discharge hematocrit of 0.4, plasma viscosity 1.0466 mPa s
// and rat red cells (55 fl), as NetFlow is set up for it. hemotree's steady solve
// (FlowNetwork: prescribed pressures eliminated, a sparse Cholesky factorisation) is checked
// against an independent solution of the same equations: the viscosity law typed anew from
// Pries et al. 1994, Poiseuille resistances, and Kirchhoff's laws for every node assembled as
// one dense system (boundary rows as identities and injected flows) and solved by Eigen's
// full-pivoting LU. Skipped without ../shared/networks.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "exchange/secomb.hpp"
#include "tests/shared_networks.hpp"
#include "steady/steady_flow.hpp"

using namespace hemotree;
namespace fs = std::filesystem;

namespace {


// Pries, Secomb, Gessner et al. 1994 (Circ Res 75:904), in vivo, D in um, with the diameter
// the cells see scaled by (92/55)^(1/3) (rat cells) as NetFlow's viscor.cpp does.
double pries_viscosity(double diameter_m, double hd, double plasma) {
  const double d = diameter_m * 1e6 * std::cbrt(92.0 / 55.0);
  const double eta45 = 6 * std::exp(-0.085 * d) + 3.2 - 2.44 * std::exp(-0.06 * std::pow(d, 0.645));
  const double s = 1 / (1 + 1e-11 * std::pow(d, 12));
  const double c = (0.8 + std::exp(-0.075 * d)) * (-1 + s) + s;
  const double k = std::pow(d / (d - 1.1), 2);
  return plasma * (1 + (eta45 - 1) * (std::pow(1 - hd, c) - 1) / (std::pow(1 - 0.45, c) - 1) * k) * k;
}

struct Spread {
  double median = 0, p95 = 0, max = 0;
};

Spread spread(std::vector<double> x) {
  std::sort(x.begin(), x.end());
  auto rank = [&](double f) { return x[static_cast<std::size_t>(std::llround(f * static_cast<double>(x.size() - 1)))]; };
  return {rank(0.5), rank(0.95), x.back()};
}

}  // namespace

TEST(MesenteryValidation, SteadyFlowsAndPressuresMatchAnIndependentDenseSolve) {
  const fs::path path = shared_mesentery();
  if (!fs::exists(path)) GTEST_SKIP() << path << " absent (the shared public networks)";
  Network net = read_secomb(path.string(), ImportOptions{});
  Blood blood;
  blood.hematocrit = 0.4;
  blood.plasma_viscosity = 1.0466e-3;
  blood.mean_cell_volume = 55e-18;
  blood.pries_max_diameter = 1;  // the law itself in every vessel (all are below 30 um here)
  net.blood = blood;
  ASSERT_EQ(net.vessel_count(), 1130u);

  const SteadyFlow s = solve_steady_flow(net);

  // The independent solution: every node a row.
  const auto nodes = static_cast<Eigen::Index>(net.node_count());
  Eigen::MatrixXd k = Eigen::MatrixXd::Zero(nodes, nodes);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(nodes);
  std::vector<double> conductance(net.vessel_count());
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    const double d = net.diameter[v];
    const double mu = pries_viscosity(d, 0.4, 1.0466e-3);
    conductance[v] = std::numbers::pi * std::pow(d, 4) / (128 * mu * net.length[v]);
    const Eigen::Index a = net.from[v], b = net.to[v];
    k(a, a) += conductance[v];
    k(b, b) += conductance[v];
    k(a, b) -= conductance[v];
    k(b, a) -= conductance[v];
  }
  // A prescribed pressure's row, g p_i = g p_given, scaled as the others (g a typical
  // conductance): the LU's rank test is relative to the largest pivot.
  std::vector<double> sorted = conductance;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
  const double g = sorted[sorted.size() / 2];
  for (const NodeBoundary& b : net.boundaries) {
    if (b.type == BoundaryType::pressure) {
      k.row(b.node).setZero();
      k(b.node, b.node) = g;
      rhs(b.node) = g * b.waveform.mean_value();
    } else {
      rhs(b.node) = b.waveform.mean_value();  // flow into the node
    }
  }
  const Eigen::VectorXd p = k.fullPivLu().solve(rhs);

  std::vector<double> dp, dq;
  double p_scale = 0, q_scale = 0;
  std::size_t sign_flips = 0;
  for (Eigen::Index i = 0; i < nodes; ++i) p_scale = std::max(p_scale, std::abs(p(i)));
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    const double q = conductance[v] * (p(net.from[v]) - p(net.to[v]));
    q_scale = std::max(q_scale, std::abs(q));
    dq.push_back(std::abs(s.flow[v] - q) / std::abs(q));
    if ((s.flow[v] > 0) != (q > 0)) ++sign_flips;
  }
  for (Eigen::Index i = 0; i < nodes; ++i)
    dp.push_back(std::abs(s.node_pressure[static_cast<std::size_t>(i)] - p(i)) / std::abs(p(i)));
  const Spread flows = spread(dq), pressures = spread(dp);
  std::printf("mesentery, constant Hd 0.4: relative flow difference median %.2g, p95 %.2g, max %.2g; pressure "
              "median %.2g, p95 %.2g, max %.2g; sign flips %zu; inflow %.6g nl/min\n",
              flows.median, flows.p95, flows.max, pressures.median, pressures.p95, pressures.max, sign_flips,
              [&] {
                double in = 0;
                for (const NodeBoundary& b : net.boundaries)
                  if (b.type == BoundaryType::flow && b.waveform.mean_value() > 0) in += b.waveform.mean_value();
                return in * 60e12;
              }());
  // Both solve one linear system in double precision; the conductances span 4 decades, so the
  // two factorisations agree to a few 1e-12 of the largest values. Relative to each vessel,
  // the flows of the loops' nearly stagnant segments carry that absolute error further.
  EXPECT_LT(pressures.max, 1e-11);  // measured 5e-14
  EXPECT_LT(flows.median, 1e-11);  // measured 2.3e-14 (largest 7.2e-13)
  for (std::size_t v = 0; v < net.vessel_count(); ++v)
    EXPECT_NEAR(s.flow[v], conductance[v] * (p(net.from[v]) - p(net.to[v])), 1e-11 * q_scale) << "vessel " << net.id[v];
  EXPECT_EQ(sign_flips, 0u);
}
