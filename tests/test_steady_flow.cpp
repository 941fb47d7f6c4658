// The steady Poiseuille-Pries solver against hand calculations.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "cli/errors.hpp"
#include "formats/network_io.hpp"
#include "physics/rheology.hpp"
#include "solver/steady_flow.hpp"
#include "tests/network_builders.hpp"

using namespace hemotree;
using test_networks::resistance_outlet;

namespace {

// root 0 -> 1, daughters 1 -> 2 and 1 -> 3
Network bifurcation(double d0, double d1, double d2) {
  Network net;
  for (int n = 0; n < 4; ++n) net.add_node(n);
  net.add_vessel(0, 0, 1, 0.01, d0, 1e-4, 2e5, 0);
  net.add_vessel(1, 1, 2, 0.02, d1, 1e-4, 2e5, 1);
  net.add_vessel(2, 1, 3, 0.03, d2, 1e-4, 2e5, 1);
  return net;
}

}  // namespace

TEST(SteadyFlow, PoiseuilleResistanceWithThePriesViscosity) {
  Network net;
  net.add_node(0);
  net.add_node(1);
  net.add_vessel(0, 0, 1, 1e-3, 10e-6, 1e-6, 2e5, 0);
  Blood blood;
  const double r = vessel_resistances(net, blood)[0];
  // eta(10 um, 0.45) = 5.8724376741789005 (tests/test_rheology.cpp's hand table)
  const double mu = 1e-3 * 5.8724376741789005;
  EXPECT_NEAR(r, 128 * mu * 1e-3 / (std::numbers::pi * std::pow(10e-6, 4)), 1e-9 * r);
  blood.rheology = Rheology::newtonian;
  EXPECT_NEAR(vessel_resistances(net, blood)[0],
              128 * 3.4e-3 * 1e-3 / (std::numbers::pi * std::pow(10e-6, 4)), 1e-9 * r);
}

TEST(SteadyFlow, SingleTubeWithAResistanceOutlet) {
  Network net;
  net.add_node(0);
  net.add_node(1);
  net.add_vessel(0, 0, 1, 0.1, 1e-3, 1e-4, 2e5, 0);
  net.outlets.push_back(resistance_outlet(0, 3e9, 1000.0));
  const std::vector<double> r{2e9};
  const SteadyFlow s = solve_steady_flow(net, r, 1e-6);
  EXPECT_DOUBLE_EQ(s.inlet_pressure, 1000.0 + 1e-6 * (2e9 + 3e9));
  EXPECT_DOUBLE_EQ(s.node_pressure[1], 1000.0 + 1e-6 * 3e9);
  EXPECT_DOUBLE_EQ(s.flow[0], 1e-6);
}

// The distended solution of a compliant tube (Newtonian blood, tube law given): its
// resistance is Poiseuille's at the lumen of its mean pressure, so the solution satisfies
// p_in - p_node = Q 8 pi mu L / A(p_mean)^2; the tube widens above p_ref, so it resists less
// than at its reference lumen and the inlet pressure falls.
TEST(SteadyFlow, DistendedTubeResistsAtTheLumenOfItsMeanPressure) {
  Network net = test_networks::chain(1, 0.05, 1e-3, 0, 1333.0, test_networks::newtonian(3.5e-3));
  const double a_ref = std::numbers::pi / 4 * 1e-6;
  net.beta[0] = test_networks::beta_for_wave_speed(3.0, a_ref);  // soft: c = 3 m/s
  net.outlets.push_back(resistance_outlet(0, 1e9, 1333.0));
  VesselLaw law;
  law.beta = net.beta[0];
  law.reference_area = a_ref;
  law.reference_pressure = 1333.0;
  law.density = test_networks::rho;
  const std::vector<VesselLaw> laws{law};
  const ViscosityTable mu(*net.blood);
  const double q = 5e-6;
  std::vector<double> r;
  const SteadyFlow s = solve_distended_steady_flow(net, *net.blood, laws, mu, q, &r);
  const double p_node = 1333.0 + q * 1e9;
  EXPECT_NEAR(s.node_pressure[1], p_node, 1e-9 * p_node);
  const double a = law.area(0.5 * (s.inlet_pressure + p_node));
  const double drop = q * 8 * std::numbers::pi * 3.5e-3 * 0.05 / (a * a);
  EXPECT_NEAR(s.inlet_pressure - p_node, drop, 1e-8 * drop);
  EXPECT_NEAR(r[0], drop / q, 1e-8 * r[0]);
  const SteadyFlow rigid = solve_steady_flow(net, vessel_resistances(net, *net.blood), q);
  EXPECT_LT(s.inlet_pressure, rigid.inlet_pressure - 0.1 * (rigid.inlet_pressure - p_node));
}

TEST(SteadyFlow, BifurcationSplitsByConductanceAndConservesMass) {
  Network net = bifurcation(1e-3, 8e-4, 6e-4);
  net.outlets.push_back(resistance_outlet(1, 4e9, 500.0));
  net.outlets.push_back(resistance_outlet(2, 6e9, 900.0));
  const std::vector<double> r{1e9, 2e9, 3e9};
  const double q = 2e-6;
  const SteadyFlow s = solve_steady_flow(net, r, q);
  // Daughters: (6e9 to 500 Pa) and (9e9 to 900 Pa) in parallel; by hand:
  // p1 = (q + 500/6e9 + 900/9e9) / (1/6e9 + 1/9e9)
  const double p1 = (q + 500 / 6e9 + 900 / 9e9) / (1 / 6e9 + 1 / 9e9);
  EXPECT_NEAR(s.node_pressure[1], p1, 1e-9 * p1);
  EXPECT_NEAR(s.flow[1], (p1 - 500) / 6e9, 1e-15);
  EXPECT_NEAR(s.flow[1] + s.flow[2], q, 1e-12 * q);
  EXPECT_NEAR(s.inlet_pressure, p1 + q * 1e9, 1e-9 * p1);
}

TEST(SteadyFlow, RefusesNetworksItCannotSolve) {
  Network net = bifurcation(1e-3, 8e-4, 6e-4);
  const std::vector<double> r{1e9, 2e9, 3e9};
  net.outlets.push_back(resistance_outlet(1, 4e9, 0));
  EXPECT_THROW(solve_steady_flow(net, r, 1e-6), InputError);  // vessel 2 has no outlet
  net.outlets.push_back(resistance_outlet(0, 4e9, 0));
  EXPECT_THROW(solve_steady_flow(net, r, 1e-6), InputError);  // vessel 0 is not terminal
  net.outlets.pop_back();
  Outlet reflecting;
  reflecting.vessel = 2;
  reflecting.type = OutletType::reflection;
  net.outlets.push_back(reflecting);
  EXPECT_THROW(solve_steady_flow(net, r, 1e-6), InputError);
  EXPECT_THROW(solve_steady_flow(bifurcation(1e-3, 8e-4, 6e-4)), InputError);  // no inlet
}
