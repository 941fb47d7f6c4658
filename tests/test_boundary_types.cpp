// Each boundary condition (boundaries/): its 1D end state against the equation its header
// claims it imposes, at both ends where it may sit, with the characteristic leaving the
// vessel kept: Q* - Q = lambda_in (A* - A) (physics/riemann.hpp); its 0D rows; and its
// steady row in the nodal system.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "boundaries/coupled_node.hpp"
#include "boundaries/flow_inlet.hpp"
#include "boundaries/pressure_end.hpp"
#include "boundaries/rcr_outlet.hpp"
#include "boundaries/reflection_outlet.hpp"
#include "boundaries/resistance_outlet.hpp"
#include "boundaries/system_rows.hpp"
#include "physics/riemann.hpp"
#include "physics/tube_law.hpp"

using namespace hemotree;

namespace {

// An artery of 2 cm diameter, wave speed about 5 m/s, and a subsonic trace at its end.
TubeLaw artery() {
  TubeLaw law;
  law.reference_area = 3.14159265358979323846e-4;
  law.density = 1050.0;
  law.beta = 2 * law.density * 25.0 / std::sqrt(law.reference_area);  // c^2 = beta sqrt(A) / (2 rho)
  law.reference_pressure = 1.0e4;
  return law;
}
constexpr double trace_area = 3.3e-4, trace_flow = 1.2e-4;

// The outgoing characteristic is kept: Q* - Q = lambda_in (A* - A).
void expect_outgoing_kept(const TubeLaw& law, double a, double q, bool distal, const EndState& u) {
  const double mu = incoming_speed(law, a, q, distal);
  EXPECT_NEAR(u.flow - q, mu * (u.area - a), 1e-12 * (std::abs(q) + std::abs(mu) * a));
}

TEST(FlowInlet, PrescribesTheInflowAtEitherEnd) {
  const TubeLaw law = artery();
  const FlowInlet inlet{2.5e-4};
  const EndState proximal = inlet.end_state(law, trace_area, trace_flow, false);
  EXPECT_DOUBLE_EQ(proximal.flow, 2.5e-4);
  expect_outgoing_kept(law, trace_area, trace_flow, false, proximal);
  // At a distal end the inflow runs against the vessel.
  const EndState distal = inlet.end_state(law, trace_area, trace_flow, true);
  EXPECT_DOUBLE_EQ(distal.flow, -2.5e-4);
  expect_outgoing_kept(law, trace_area, trace_flow, true, distal);
}

TEST(PressureEnd, TheEndsTotalPressureIsTheNodes) {
  const TubeLaw law = artery();
  const PressureEnd end{1.3e4};
  for (const bool distal : {false, true}) {
    const EndState u = end.end_state(law, trace_area, trace_flow, distal);
    EXPECT_NEAR(law.total_pressure(u.area, u.flow), 1.3e4, 1e-9 * 1.3e4) << "distal " << distal;
    expect_outgoing_kept(law, trace_area, trace_flow, distal, u);
  }
}

TEST(ResistanceOutlet, PressureDropIsResistanceTimesFlow) {
  const TubeLaw law = artery();
  const ResistanceOutlet outlet{1.0e8, 2.0e3};
  const EndState u = outlet.end_state(law, trace_area, trace_flow);
  EXPECT_NEAR(law.pressure(u.area) - outlet.p_out, outlet.resistance * u.flow, 1e-9 * law.pressure(u.area));
  expect_outgoing_kept(law, trace_area, trace_flow, true, u);
}

TEST(RcrOutlet, R1ToTheCapacitorAndTheCapacitorsRate) {
  const TubeLaw law = artery();
  const RcrOutlet outlet{2.0e7, 1.0e-8, 8.0e7, 1.5e3};
  const double p_c = 9.0e3;
  const EndState u = outlet.end_state(law, trace_area, trace_flow, p_c);
  EXPECT_NEAR(law.pressure(u.area) - p_c, outlet.r1 * u.flow, 1e-9 * law.pressure(u.area));
  expect_outgoing_kept(law, trace_area, trace_flow, true, u);
  // C dp_c/dt = Q* - (p_c - p_out) / R2
  EXPECT_DOUBLE_EQ(outlet.capacitor_rate(u.flow, p_c), (u.flow - (p_c - outlet.p_out) / outlet.r2) / outlet.c);
  // Without compliance, R1 and R2 in series to p_out.
  const EndState series = outlet.series_end_state(law, trace_area, trace_flow);
  EXPECT_NEAR(law.pressure(series.area) - outlet.p_out, (outlet.r1 + outlet.r2) * series.flow,
              1e-9 * law.pressure(series.area));
  expect_outgoing_kept(law, trace_area, trace_flow, true, series);
}

TEST(LumpedRows, AnROutletIsAShuntAndAnRcrACapacitorNode) {
  const ResistanceOutlet r{4e8, 1.5e3};
  EXPECT_EQ(r.lumped_shunt().conductance, 1 / 4e8);
  EXPECT_EQ(r.lumped_shunt().pressure, 1.5e3);
  const RcrOutlet rcr{1e8, 2e-9, 3e8, 1.5e3};
  const LumpedCapacitor cap = rcr.lumped_capacitor();
  EXPECT_EQ(cap.edge_resistance, 1e8);
  EXPECT_EQ(cap.shunt.conductance, 1 / 3e8);
  EXPECT_EQ(cap.shunt.pressure, 1.5e3);
  EXPECT_EQ(cap.compliance, 2e-9);
  // With no compliance, R1 and R2 in series: the R outlet's shunt.
  EXPECT_EQ(rcr.series_lumped_shunt().conductance, r.lumped_shunt().conductance);
  EXPECT_EQ(rcr.series_lumped_shunt().pressure, r.lumped_shunt().pressure);
}

TEST(ReflectionOutlet, TheIncomingWaveIsMinusRtTimesTheOutgoing) {
  const TubeLaw law = artery();
  const double a0 = law.reference_area, q0 = 1.0e-4;
  for (const double rt : {0.0, 0.3, -0.6}) {
    const ReflectionOutlet outlet{rt, a0, q0};
    const EndState u = outlet.end_state(law, trace_area, trace_flow);
    // Measured from rest: w_in = l_in(U0) . (U* - U0), l_in(U0) = (-lambda_forward0, 1);
    // w_out with (-lambda_backward0, 1).
    const double w_in = -law.lambda_forward(a0, q0) * (u.area - a0) + (u.flow - q0);
    const double w_out = -law.lambda_backward(a0, q0) * (u.area - a0) + (u.flow - q0);
    EXPECT_NEAR(w_in, -rt * w_out, 1e-9 * std::abs(law.lambda_forward(a0, q0) * (u.area - a0))) << "rt " << rt;
    expect_outgoing_kept(law, trace_area, trace_flow, true, u);
  }
}

TEST(CoupledNode, TheEndsTotalPressureIsTheNodesPlusItsResponse) {
  const TubeLaw law = artery();
  const CoupledNode node{1.1e4, 40.0, 5.0e6, 3.0e-5};
  for (const bool distal : {false, true}) {
    const EndState u = node.end_state(law, trace_area, trace_flow, distal);
    const double q_in = CoupledNode::flow_into_node(u, distal);
    EXPECT_EQ(q_in, distal ? u.flow : -u.flow);
    // p(A*) + rho u*^2 / 2 = p + p_dyn + r (Q_in - Q_held)
    EXPECT_NEAR(law.total_pressure(u.area, u.flow),
                node.pressure + node.dynamic_pressure + node.response * (q_in - node.held_flow), 1e-9 * 1.1e4)
        << "distal " << distal;
    expect_outgoing_kept(law, trace_area, trace_flow, distal, u);
  }
}

TEST(PressureEnd, ItsZeroDShuntHoldsTheNodeTo1e10OfTheVesselsDrop) {
  // A node joined by one vessel of conductance g to a neighbour at p_n, held to p by the
  // shunt: its pressure (g p_n + G p_s) / (g + G) departs from p by g / (g + G) of the drop.
  const double g = 3e-12, p = 1.1e4, p_n = 1.4e4;
  const LumpedShunt held = PressureEnd{p}.held_shunt(g);
  EXPECT_EQ(held.pressure, p);
  const double node = (g * p_n + held.conductance * held.pressure) / (g + held.conductance);
  EXPECT_NEAR((node - p) / (p_n - p), 1e-10, 1e-15);
}

// Three nodes' rows, empty.
struct Rows {
  std::vector<double> shunt = std::vector<double>(3, 0.0), inflow = std::vector<double>(3, 0.0),
                      pressure = std::vector<double>(3, 0.0);
  std::vector<unsigned char> prescribed = std::vector<unsigned char>(3, 0);
  NodalRows rows{shunt, inflow, pressure, prescribed};
};

TEST(SteadyRows, AFlowIsACurrentIntoItsNode) {
  Rows r;
  FlowInlet{2e-6}.add_steady_row(r.rows, 1);
  FlowInlet{-5e-7}.add_steady_row(r.rows, 1);
  EXPECT_DOUBLE_EQ(r.inflow[1], 2e-6 - 5e-7);
  EXPECT_EQ(r.shunt, std::vector<double>(3, 0.0));
  EXPECT_EQ(r.prescribed, std::vector<unsigned char>(3, 0));
}

TEST(SteadyRows, APressureIsPrescribed) {
  Rows r;
  PressureEnd{1.2e4}.add_steady_row(r.rows, 2);
  EXPECT_EQ(r.prescribed, (std::vector<unsigned char>{0, 0, 1}));
  EXPECT_EQ(r.pressure[2], 1.2e4);
  EXPECT_EQ(r.inflow, std::vector<double>(3, 0.0));
}

TEST(SteadyRows, AnOutletIsAShuntToItsOutflowPressure) {
  // Q = (p_i - p_out) / R: G_i = 1/R, b_i = p_out / R.
  Rows r;
  ResistanceOutlet{4e8, 1.5e3}.add_steady_row(r.rows, 0);
  EXPECT_EQ(r.shunt[0], 1 / 4e8);
  EXPECT_EQ(r.inflow[0], 1.5e3 / 4e8);
  // An RCR's capacitor carries no steady flow: R1 + R2 in series.
  Rows rcr;
  RcrOutlet{1e8, 2e-9, 3e8, 1.5e3}.add_steady_row(rcr.rows, 0);
  EXPECT_EQ(rcr.shunt, r.shunt);
  EXPECT_EQ(rcr.inflow, r.inflow);
}

}  // namespace
