// The steady Poiseuille-Pries solver against hand calculations.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "formats/network_io.hpp"
#include "formats/pressure_reference.hpp"
#include "physics/rheology.hpp"
#include "steady/loaded_tree.hpp"
#include "steady/steady_flow.hpp"
#include "tests/network_builders.hpp"

using namespace hemotree;
using test_networks::flow_boundary;
using test_networks::pressure_boundary;
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
  TubeLaw law;
  law.beta = net.beta[0];
  law.reference_area = a_ref;
  law.reference_pressure = 1333.0;
  law.density = test_networks::rho;
  const std::vector<TubeLaw> laws{law};
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
  reflecting.type = BoundaryType::reflection;
  net.outlets.push_back(reflecting);
  EXPECT_THROW(solve_steady_flow(net, r, 1e-6), InputError);
  EXPECT_THROW(solve_steady_flow(bifurcation(1e-3, 8e-4, 6e-4)), InputError);  // no inlet
}

// A network with a loop: vessel 0 splits at node 1 into two branches (vessels 1 then 3, and
// 2 then 4) that rejoin at node 4, and vessel 5 leads to the one outlet. By hand: the whole
// inflow passes vessels 0 and 5 and the outlet, and the branches (3 + 4 = 7 and 2 + 8 = 10,
// in 1e9 Pa s/m^3) share it in inverse proportion to their resistances: in parallel, 70/17.
TEST(SteadyFlow, ALoopSplitsTheFlowAsParallelResistances) {
  Network net;
  for (int n = 0; n < 6; ++n) net.add_node(n);
  const int from[] = {0, 1, 1, 2, 3, 4}, to[] = {1, 2, 3, 4, 4, 5};
  for (int v = 0; v < 6; ++v) net.add_vessel(v, from[v], to[v], 0.01, 1e-3, 1e-4, 2e5, v == 0 ? 0 : 1);
  net.outlets.push_back(resistance_outlet(5, 7e9, 1000.0));
  const std::vector<double> r{1e9, 3e9, 2e9, 4e9, 8e9, 6e9};
  const double q = 2e-6;
  const SteadyFlow s = solve_steady_flow(net, r, q);
  const double p5 = 1000 + q * 7e9, p4 = p5 + q * 6e9;
  const double r_a = 3e9 + 4e9, r_b = 2e9 + 8e9, parallel = r_a * r_b / (r_a + r_b);
  const double p1 = p4 + q * parallel, q_a = q * r_b / (r_a + r_b), q_b = q - q_a;
  EXPECT_NEAR(s.node_pressure[5], p5, 1e-12 * p5);
  EXPECT_NEAR(s.node_pressure[4], p4, 1e-12 * p4);
  EXPECT_NEAR(s.node_pressure[1], p1, 1e-12 * p1);
  EXPECT_NEAR(s.node_pressure[2], p1 - q_a * 3e9, 1e-12 * p1);
  EXPECT_NEAR(s.node_pressure[3], p1 - q_b * 2e9, 1e-12 * p1);
  EXPECT_NEAR(s.inlet_pressure, p1 + q * 1e9, 1e-12 * p1);
  EXPECT_NEAR(s.node_pressure[0], s.inlet_pressure, 0.0);
  const double expected_flow[] = {q, q_a, q_b, q_a, q_b, q};
  for (int v = 0; v < 6; ++v) EXPECT_NEAR(s.flow[v], expected_flow[v], 1e-12 * q) << "vessel " << v;
  // The loaded network (its outflow pressures zero) with the inflow injected at the inlet's
  // node is the same system: its potentials are the pressures above p_out.
  TreeLoads loads;
  loads.node_shunt.assign(6, 0.0);
  loads.node_current.assign(6, 0.0);
  loads.node_current[0] = q;
  loads.capacitor_shunt.assign(1, 0.0);
  loads.capacitor_current.assign(1, 0.0);
  const TreePotentials loaded = solve_loaded_tree(net, r, loads);
  for (std::size_t k = 0; k < 6; ++k)
    EXPECT_NEAR(loaded.node[k], s.node_pressure[k] - 1000, 1e-12 * p1) << "node " << k;
  // Through the network's own file fields too: with an inlet, blood, and Poiseuille resistances
  // it solves (the equal branches then split the flow evenly).
  net.inlet = Inlet{};
  net.inlet->waveform.mean = q;
  const SteadyFlow own = solve_steady_flow(net);
  EXPECT_NEAR(own.flow[1], q / 2, 1e-12 * q);
  EXPECT_NEAR(own.flow[5], q, 1e-12 * q);
  // The two branches as two vessels between the same nodes 1 and 2 (2 and 4 in parallel,
  // 4/3), then vessel 3 to the outlet.
  Network doubled;
  for (int n = 0; n < 4; ++n) doubled.add_node(n);
  doubled.add_vessel(0, 0, 1, 0.01, 1e-3, 1e-4, 2e5, 0);
  doubled.add_vessel(1, 1, 2, 0.01, 1e-3, 1e-4, 2e5, 1);
  doubled.add_vessel(2, 1, 2, 0.01, 1e-3, 1e-4, 2e5, 1);
  doubled.add_vessel(3, 2, 3, 0.01, 1e-3, 1e-4, 2e5, 2);
  doubled.outlets.push_back(resistance_outlet(3, 7e9, 1000.0));
  const SteadyFlow d = solve_steady_flow(doubled, {1e9, 2e9, 4e9, 6e9}, q);
  EXPECT_NEAR(d.inlet_pressure, 1000 + q * (1e9 + 4e9 / 3 + 6e9 + 7e9), 1e-12 * d.inlet_pressure);
  EXPECT_NEAR(d.flow[1], 2 * q / 3, 1e-12 * q);
  EXPECT_NEAR(d.flow[2], q / 3, 1e-12 * q);
  // A loop is no rooted tree: the Thevenin equivalents (reduce_beyond) refuse it.
  std::vector<Equivalent> beyond;
  EXPECT_THROW(solve_steady_flow(net, r, q, &beyond), InputError);
}

// Where the network does not hang together as one inflow to its outlets.
TEST(SteadyFlow, RefusesOpenEndsAndPartsApartFromTheInlet) {
  auto expect_refusal = [&](const Network& net, const std::string& fragment) {
    try {
      solve_steady_flow(net, std::vector<double>(net.vessel_count(), 1e9), 1e-6);
      ADD_FAILURE() << "no refusal, expected: " << fragment;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  // A second vessel fed by no vessel: 0 -> 1 <- 2, then 1 -> 3.
  Network two_roots;
  for (int n = 0; n < 4; ++n) two_roots.add_node(n);
  two_roots.add_vessel(0, 0, 1, 0.01, 1e-3, 1e-4, 2e5, 0);
  two_roots.add_vessel(1, 2, 1, 0.01, 1e-3, 1e-4, 2e5, 0);
  two_roots.add_vessel(2, 1, 3, 0.01, 1e-3, 1e-4, 2e5, 1);
  two_roots.outlets.push_back(resistance_outlet(2, 1e9, 0));
  expect_refusal(two_roots, "vessel 0 and vessel 1 are both fed by no vessel");
  two_roots.inlet = Inlet{};
  expect_refusal(two_roots, "vessel 1 is fed by no vessel and does not start at the inlet");
  two_roots.inlet->vessel = 2;
  expect_refusal(two_roots, "inlet: vessel 2 is not a root");
  // A closed loop beside the tree, drained by an outlet: 0 -> 1 (outlet), and 2 -> 3 -> 4 -> 2
  // with 4 -> 5 (outlet).
  Network apart;
  for (int n = 0; n < 6; ++n) apart.add_node(n);
  apart.add_vessel(0, 0, 1, 0.01, 1e-3, 1e-4, 2e5, 0);
  apart.add_vessel(1, 2, 3, 0.01, 1e-3, 1e-4, 2e5, 0);
  apart.add_vessel(2, 3, 4, 0.01, 1e-3, 1e-4, 2e5, 0);
  apart.add_vessel(3, 4, 2, 0.01, 1e-3, 1e-4, 2e5, 0);
  apart.add_vessel(4, 4, 5, 0.01, 1e-3, 1e-4, 2e5, 0);
  apart.outlets = {resistance_outlet(0, 1e9, 0), resistance_outlet(4, 1e9, 0)};
  expect_refusal(apart, "vessel 1 is not connected to the inlet");
  // A loop without a way out: 0 -> 1 -> 2 -> 1, no terminal vessel, no outlet.
  Network closed;
  for (int n = 0; n < 3; ++n) closed.add_node(n);
  closed.add_vessel(0, 0, 1, 0.01, 1e-3, 1e-4, 2e5, 0);
  closed.add_vessel(1, 1, 2, 0.01, 1e-3, 1e-4, 2e5, 1);
  closed.add_vessel(2, 2, 1, 0.01, 1e-3, 1e-4, 2e5, 1);
  expect_refusal(closed, "no outlet");
}

// ---- boundaries at nodes (format version 2): loops, several inlets, prescribed pressures ----

namespace {

// A diamond with a bridge: flow Q into node 0, node 3 held at P; vessels 0: 0->1, 1: 0->2,
// 2: 1->3, 3: 3->2 (written against its flow), 4: 1->2 (the bridge), resistances r, r, r, 2r, r.
Network bridged_diamond(double q, double p) {
  Network net;
  for (int n = 0; n < 4; ++n) net.add_node(n);
  const int from[] = {0, 0, 1, 3, 1}, to[] = {1, 2, 3, 2, 2};
  for (int v = 0; v < 5; ++v) net.add_vessel(v, from[v], to[v], 0.01, 1e-3, 1e-4, 2e5, 0);
  net.boundaries = {flow_boundary(0, q), pressure_boundary(3, p)};
  return net;
}

}  // namespace

// Kirchhoff by hand (r = 1e9 Pa s/m^3, Q = 1e-9 m^3/s, so pressures above P in Pa):
// 2 p0 - p1 - p2 = 1, 3 p1 - p0 - p2 = 0, 2.5 p2 - p0 - p1 = 0 give p0 = 13/11, p1 = 7/11,
// p2 = 8/11; the flows 6/11, 5/11, 7/11, -4/11 (against its from -> to), -1/11.
TEST(SteadyFlowAtNodes, LoopedNetworkMatchesKirchhoffByHand) {
  const double r = 1e9, q = 1e-9, p = 1000;
  const Network net = bridged_diamond(q, p);
  const SteadyFlow s = solve_steady_flow(net, {r, r, r, 2 * r, r}, 0.0);
  const double expected_p[] = {13.0 / 11, 7.0 / 11, 8.0 / 11, 0};
  for (int n = 0; n < 4; ++n) EXPECT_NEAR(s.node_pressure[n], p + expected_p[n], 1e-12 * p) << "node " << n;
  const double expected_q[] = {6.0 / 11, 5.0 / 11, 7.0 / 11, -4.0 / 11, -1.0 / 11};
  for (int v = 0; v < 5; ++v) EXPECT_NEAR(s.flow[v], q * expected_q[v], 1e-12 * q) << "vessel " << v;
  EXPECT_TRUE(std::isnan(s.inlet_pressure));  // no tree inlet
}

// Several inflows and outflows, one pressure, an R outlet: whatever enters leaves.
TEST(SteadyFlowAtNodes, SeveralInletsAndOutletsBalance) {
  // A ladder: rails 0-1-2-3 and 4-5-6-7, rungs i <-> i + 4.
  Network net;
  for (int n = 0; n < 8; ++n) net.add_node(n);
  int id = 0;
  for (int i = 0; i < 3; ++i) net.add_vessel(id++, i, i + 1, 0.01, 1e-3, 1e-4, 2e5, 0);
  for (int i = 4; i < 7; ++i) net.add_vessel(id++, i + 1, i, 0.01, 1e-3, 1e-4, 2e5, 0);
  for (int i = 0; i < 4; ++i) net.add_vessel(id++, i, i + 4, 0.01, 0.8e-3, 1e-4, 2e5, 0);
  NodeBoundary outlet;
  outlet.node = 7;
  outlet.type = BoundaryType::resistance;
  outlet.outlet = resistance_outlet(-1, 5e8, 200.0);
  net.boundaries = {flow_boundary(0, 2e-9), flow_boundary(3, 1e-9), flow_boundary(5, -0.5e-9), pressure_boundary(4, 100.0), outlet};
  std::sort(net.boundaries.begin(), net.boundaries.end(),
            [](const NodeBoundary& a, const NodeBoundary& b) { return a.node < b.node; });
  std::vector<double> r(net.vessel_count());
  for (std::size_t v = 0; v < r.size(); ++v) r[v] = 1e9 * (1 + 0.1 * static_cast<double>(v));
  const SteadyFlow s = solve_steady_flow(net, r, 0.0);
  // Net flow out of every node into its vessels.
  std::vector<double> out(8, 0.0);
  for (std::size_t v = 0; v < r.size(); ++v) {
    out[net.from[v]] += s.flow[v];
    out[net.to[v]] -= s.flow[v];
  }
  const double scale = 1e-9, tol = 1e-12 * scale;
  EXPECT_NEAR(out[0], 2e-9, tol);
  EXPECT_NEAR(out[3], 1e-9, tol);
  EXPECT_NEAR(out[5], -0.5e-9, tol);
  for (int n : {1, 2, 6}) EXPECT_NEAR(out[n], 0.0, tol) << "node " << n;
  EXPECT_DOUBLE_EQ(s.node_pressure[4], 100.0);
  EXPECT_NEAR(-out[7], (s.node_pressure[7] - 200.0) / 5e8, tol);  // the outlet's law
  EXPECT_NEAR(out[4] + out[7], -(2e-9 + 1e-9 - 0.5e-9), tol);    // the rest leaves at 4 and 7
}

TEST(SteadyFlowAtNodes, RefusesNetworksWithoutAPressureReference) {
  auto expect_refusal = [&](const Network& net, const std::string& fragment) {
    try {
      solve_steady_flow(net, std::vector<double>(net.vessel_count(), 1e9), 0.0);
      ADD_FAILURE() << "no refusal, expected: " << fragment;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  Network flows_only = bridged_diamond(1e-9, 0);
  flows_only.boundaries[1] = flow_boundary(3, -1e-9);
  expect_refusal(flows_only, "the network has no pressure to refer to (give a node a pressure or an outlet");
  expect_refusal(flows_only, ": the part with vessel 0 (5 vessels) has flow boundaries only: its pressure is undetermined "
                             "(at nodes 0, 3; the flows balance)");
  // A second part, 4 -> 5 -> 6 -> 4, with no boundary at all.
  Network apart = bridged_diamond(1e-9, 0);
  for (int n = 4; n < 7; ++n) apart.add_node(n);
  apart.add_vessel(5, 4, 5, 0.01, 1e-3, 1e-4, 2e5, 0);
  apart.add_vessel(6, 5, 6, 0.01, 1e-3, 1e-4, 2e5, 0);
  apart.add_vessel(7, 6, 4, 0.01, 1e-3, 1e-4, 2e5, 0);
  expect_refusal(apart, "1 of the network's 2 connected parts has no pressure to refer to");
  expect_refusal(apart, ": the part with vessel 5 (3 vessels) has no boundary condition: it is cut off from every "
                        "inflow and outflow");
  // A dead end: 2 -> 4 with nothing at node 4.
  Network dead = bridged_diamond(1e-9, 0);
  dead.add_node(4);
  dead.add_vessel(5, 2, 4, 0.01, 1e-3, 1e-4, 2e5, 0);
  expect_refusal(dead, "vessel 5 ends at node 4, which no other vessel meets and which has no boundary condition");
  {  // Every dead end in the one line: a measured network's fragments end in many.
    Network many = dead;
    for (int k = 0; k < 7; ++k) {
      const auto end = many.add_node(10 + k);
      many.add_vessel(10 + k, 1, end, 0.01, 1e-3, 1e-4, 2e5, 0);
    }
    expect_refusal(many, "vessel 5 ends at node 4");
    expect_refusal(many, "; 7 more dead ends, at nodes 10, 11, 12, 13, 14 and 2 more");
  }
  dead.boundaries.push_back(flow_boundary(4, 0.0));  // closed: accepted, and it carries nothing
  const SteadyFlow closed = solve_steady_flow(dead, std::vector<double>(6, 1e9), 0.0);
  EXPECT_NEAR(closed.flow[5], 0.0, 1e-24);
  Network reflecting = bridged_diamond(1e-9, 0);
  reflecting.boundaries[1].type = BoundaryType::reflection;
  expect_refusal(reflecting, "node 3: a reflection outlet has no steady resistance");
}

// A measured network comes in parts, most of them fragments: every part without a pressure to
// refer to is named in the one refusal, largest first, with its boundary nodes (five, then how
// many more) and whether its flows balance.
TEST(SteadyFlowAtNodes, RefusalNamesEveryPartWithoutAPressureReference) {
  Network net = bridged_diamond(1e-9, 0);  // vessels 0-4, a pressure at node 3: referred
  auto add_node = [&](std::int64_t id) { return net.add_node(id); };
  auto add_vessel = [&](std::int64_t id, std::int32_t from, std::int32_t to) {
    net.add_vessel(id, from, to, 0.01, 1e-3, 1e-4, 2e5, 0);
  };
  // A star of 7 arms from hub 10, flows at its 7 tips summing to 1e-12 m^3/s (0.00006 ml/min).
  const std::int32_t hub = add_node(10);
  for (int k = 0; k < 7; ++k) {
    const std::int32_t tip = add_node(11 + k);
    add_vessel(20 + k, hub, tip);
    net.boundaries.push_back(flow_boundary(tip, k < 6 ? 1e-9 : -6e-9 + 1e-12));
  }
  // A closed triangle (vessels 40-42) with no boundary, and a single vessel 30 whose ends carry
  // balancing flows.
  const std::int32_t a = add_node(30), b = add_node(31), c = add_node(32);
  add_vessel(40, a, b);
  add_vessel(41, b, c);
  add_vessel(42, c, a);
  const std::int32_t d = add_node(40), e = add_node(41);
  add_vessel(30, d, e);
  net.boundaries.push_back(flow_boundary(d, 2e-9));
  net.boundaries.push_back(flow_boundary(e, -2e-9));
  try {
    solve_steady_flow(net, std::vector<double>(net.vessel_count(), 1e9), 0.0);
    ADD_FAILURE() << "no refusal";
  } catch (const InputError& error) {
    const std::string what = error.what();
    EXPECT_EQ(what.find('\n'), std::string::npos) << "one line";
    EXPECT_EQ(what.rfind("3 of the network's 4 connected parts have no pressure to refer to", 0), 0u) << what;
    const std::string star = "the part with vessel 20 (7 vessels) has flow boundaries only: its pressure is "
                             "undetermined (at nodes 11, 12, 13, 14, 15 and 2 more; the net inflow is 6e-05 ml/min)";
    const std::string triangle = "the part with vessel 40 (3 vessels) has no boundary condition";
    const std::string single = "the part with vessel 30 (1 vessel) has flow boundaries only: its pressure is "
                               "undetermined (at nodes 40, 41; the flows balance)";
    for (const std::string& part : {star, triangle, single}) EXPECT_NE(what.find(part), std::string::npos) << part << "\n" << what;
    EXPECT_LT(what.find(star), what.find(triangle)) << "largest first";
    EXPECT_LT(what.find(triangle), what.find(single));
    EXPECT_EQ(what.find("vessel 0 "), std::string::npos) << "the referred part is not named: " << what;
  }
}

// A part with flow boundaries only whose flows balance: its flows follow from them alone, and a
// pressure fixed at any one node (fix_pressure_at) sets the level without changing them. The
// bridged diamond with Q in at node 0 and out at node 3 carries Kirchhoff's flows by hand
// (LoopedNetworkMatchesKirchhoffByHand), wherever its pressure is fixed.
TEST(SteadyFlowAtNodes, ABalancedFlowsOnlyPartSolvesWithAPressureFixedAtANode) {
  const double r = 1e9, q = 1e-9;
  const std::vector<double> resistance{r, r, r, 2 * r, r};
  const double expected_q[] = {6.0 / 11, 5.0 / 11, 7.0 / 11, -4.0 / 11, -1.0 / 11};
  const double expected_p[] = {13.0 / 11, 7.0 / 11, 8.0 / 11, 0};  // above node 3's [Pa]
  for (const std::int64_t node : {1, 2}) {
    Network net = bridged_diamond(q, 0);
    net.boundaries[1] = flow_boundary(3, -q);
    EXPECT_THROW(solve_steady_flow(net, resistance, 0.0), InputError);
    const double level = 1333.0;
    fix_pressure_at(net, node, level);
    const SteadyFlow s = solve_steady_flow(net, resistance, 0.0);
    for (int v = 0; v < 5; ++v) EXPECT_NEAR(s.flow[v], q * expected_q[v], 1e-12 * q) << "vessel " << v;
    EXPECT_DOUBLE_EQ(s.node_pressure[static_cast<std::size_t>(node)], level);
    const double offset = level - expected_p[node];
    for (int n = 0; n < 4; ++n) EXPECT_NEAR(s.node_pressure[n], offset + expected_p[n], 1e-12 * level) << "node " << n;
    // The fixed node takes up nothing: what enters it leaves it.
    double out_of_node = 0;
    for (std::size_t v = 0; v < 5; ++v) {
      if (net.from[v] == node) out_of_node += s.flow[v];
      if (net.to[v] == node) out_of_node -= s.flow[v];
    }
    EXPECT_NEAR(out_of_node, 0.0, 1e-12 * q) << "node " << node;
  }
}

// A tapered vessel resists as the integral of Poiseuille's law along it: for Newtonian
// blood and a radius linear from r0 to r1, R = 8 mu L (r0^2 + r0 r1 + r1^2) / (3 pi r0^3 r1^3).
TEST(SteadyFlow, TaperedVesselResistsAsTheIntegralAlongIt) {
  Network net;
  net.add_node(0);
  net.add_node(1);
  net.add_vessel(0, 0, 1, 0.02, 4e-3, 4e-4, 4e5, 0);
  net.distal_diameter = {2e-3};
  Blood blood;
  blood.rheology = Rheology::newtonian;
  const double r0 = 2e-3, r1 = 1e-3, mu = blood.newtonian_viscosity;
  const double expected = 8 * mu * 0.02 * (r0 * r0 + r0 * r1 + r1 * r1) / (3 * std::numbers::pi * std::pow(r0 * r1, 3));
  EXPECT_NEAR(vessel_resistances(net, blood)[0], expected, 1e-12 * expected);
}
