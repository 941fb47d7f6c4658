// Tracers riding on their carriers (transport/tracer_transport, transport/indicator_curves):
// a bolus through a vessel keeps its amount, stays within [0, c0] and leaves with the mean
// transit time its carrier's volume over its flux gives; red cells cross a narrow vessel
// faster than plasma (the Fahraeus effect: V H_T / (Q H_D) against V (1 - H_T) / (Q (1 - H_D)));
// a step of plasma tracer fills both daughters of a separating bifurcation to the injected
// concentration per plasma volume; the curves' landmarks against hand-made curves.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "core/errors.hpp"
#include "physics/phase_separation.hpp"
#include "tests/transport_grids.hpp"
#include "transport/indicator_curves.hpp"
#include "transport/red_cell_transport.hpp"
#include "transport/tracer_transport.hpp"

namespace hemotree {
namespace {

using namespace test_grids;
constexpr double nan = std::numeric_limits<double>::quiet_NaN();

// Runs a bolus of concentration 1 for `bolus` steps of dt into a vessel of n slices carrying
// q_dt a step, for `steps` steps; returns the outflow's curve landmarks (face n).
struct Bolus {
  double amount_error = 0, lowest = 1, highest = 0;
  IndicatorCurves::Landmarks outflow;
};
Bolus run_bolus(RedCellTransport& cells, TracerCarrier carrier, int n, double q_dt, int bolus, int steps) {
  TracerTransport tracer(cells.grid().cell_count(), 2, carrier);
  IndicatorCurves curve(1, 1.0, 0.5 * bolus, false);  // time in steps: the bolus is centred at bolus / 2
  Bolus b;
  for (int s = 0; s < steps; ++s) {
    cells.step(along(n, q_dt), std::vector<double>{0.45, nan});
    const std::vector<double> inflow{s < bolus ? 1.0 : 0.0, nan};
    tracer.step(cells, inflow, {});
    curve.add(0, s, s + 1, tracer.inflowing(static_cast<std::size_t>(n), cells, inflow, {}));
    for (const double c : tracer.concentration()) {
      b.lowest = std::min(b.lowest, c);
      b.highest = std::max(b.highest, c);
    }
    const double balance = tracer.amount(cells) - (tracer.entered() - tracer.left() + tracer.adjusted());
    b.amount_error = std::max(b.amount_error, std::abs(balance) / std::max(tracer.entered(), 1e-300));
  }
  b.outflow = curve.landmarks(steps);
  return b;
}

TEST(TracerTransport, BolusKeepsItsAmountAndBoundsAndTakesTheVolumeOverTheFlow) {
  const int n = 50;
  const double volume = 1e-13, q_dt = 0.25 * volume;  // 200 steps to cross the vessel
  RedCellTransport cells(vessel(n), std::vector<double>(n, volume), 0.45);  // no Fahraeus: k = 1
  const Bolus b = run_bolus(cells, TracerCarrier::plasma, n, q_dt, 10, 1200);
  EXPECT_LT(b.amount_error, 1e-13);
  EXPECT_GE(b.lowest, 0);
  EXPECT_LE(b.highest, 1 + 1e-15);
  // The mean transit time of a chain of implicit upwind cells: its volume over its flow, to
  // a step (where in a step the outflow is sampled).
  EXPECT_NEAR(b.outflow.mean_transit[0], n * volume / q_dt, 1.0);
  EXPECT_GT(b.outflow.arrival[0], 0);
  EXPECT_LT(b.outflow.arrival[0], b.outflow.peak_time[0]);
}

TEST(TracerTransport, RedCellsCrossANarrowVesselFasterThanPlasma) {
  const int n = 40;
  const double volume = 1e-14, q_dt = 0.2 * volume, hd = 0.45, d = 6e-6;
  const double ht = tube_hematocrit(hd, d);
  double transit[2];
  for (const TracerCarrier carrier : {TracerCarrier::cells, TracerCarrier::plasma}) {
    RedCellTransport cells(vessel(n, fahraeus_parameter(d), d), std::vector<double>(n, volume), hd);
    const Bolus b = run_bolus(cells, carrier, n, q_dt, 5, 3000);
    EXPECT_LT(b.amount_error, 1e-12);
    transit[carrier == TracerCarrier::cells ? 0 : 1] = b.outflow.mean_transit[0];
  }
  const double blood = n * volume / q_dt;
  EXPECT_NEAR(transit[0], blood * ht / hd, 1.0);              // cells: faster than the blood
  EXPECT_NEAR(transit[1], blood * (1 - ht) / (1 - hd), 1.0);  // plasma: slower
  EXPECT_LT(transit[0], 0.8 * transit[1]);
}

TEST(TracerTransport, PlasmaStepFillsBothDaughtersOfASeparatingNode) {
  // feed slice -> node (no volume) -> two daughter slices -> outlets; 30 % of the flow into the
  // narrow daughter, which the law gives far fewer red cells.
  TransportGrid g;
  g.boundaries = 3;
  g.add_cell(-1, 1);  // 0 feed
  g.add_cell(5, 1);   // 1 node
  g.add_cell(-1, 1);  // 2 narrow daughter
  g.add_cell(-1, 1);  // 3 wide daughter
  g.add_face(0, TransportGrid::boundary_side(0), 0, 10e-6);
  g.add_face(0, 1, 0, 10e-6);
  g.add_face(1, 2, 1, 5e-6);
  g.add_face(2, TransportGrid::boundary_side(1), 1, 5e-6);
  g.add_face(1, 3, 2, 9e-6);
  g.add_face(3, TransportGrid::boundary_side(2), 2, 9e-6);
  RedCellTransport cells(g, std::vector<double>{1e-13, 0, 1e-13, 1e-13}, 0.45);
  TracerTransport plasma(4, 3, TracerCarrier::plasma), blood(4, 3, TracerCarrier::blood);
  const double q = 2e-14;
  for (int s = 0; s < 2000; ++s) {
    cells.step(std::vector<double>{-q, q, 0.3 * q, 0.3 * q, 0.7 * q, 0.7 * q}, std::vector<double>{0.45, nan, nan});
    plasma.step(cells, std::vector<double>{1.0, nan, nan}, {});
    blood.step(cells, std::vector<double>{1.0, nan, nan}, {});
  }
  const auto h = cells.discharge_hematocrit();
  ASSERT_LT(h[2], 0.43);  // skimmed
  ASSERT_GT(h[3], 0.45);
  for (std::size_t c : {2, 3}) {
    EXPECT_NEAR(plasma.concentration()[c], 1.0, 1e-12);  // per plasma volume, whatever the split
    EXPECT_NEAR(blood.concentration()[c], 1.0, 1e-12);   // per blood volume, too
  }
}

TEST(TracerTransport, InjectionAtAFaceIsCountedApart) {
  const int n = 10;
  RedCellTransport cells(vessel(n), std::vector<double>(n, 1e-13), 0.45);
  TracerTransport tracer(static_cast<std::size_t>(n), 2, TracerCarrier::blood);
  const Injection injected{5, 2.0};  // into slice 5 with the blood crossing face 5
  for (int s = 0; s < 30; ++s) {
    cells.step(along(n, 0.5e-13), std::vector<double>{0.45, nan});
    tracer.step(cells, std::vector<double>{0.0, nan}, s < 4 ? injected : Injection{});
  }
  EXPECT_NEAR(tracer.injected(), 4 * 0.5e-13 * 2.0, 1e-27);
  EXPECT_EQ(tracer.entered(), 0.0);
  EXPECT_NEAR(tracer.amount(cells) + tracer.left(), tracer.injected(), 1e-13 * tracer.injected());
  for (int i = 0; i < 5; ++i) EXPECT_EQ(tracer.concentration()[static_cast<std::size_t>(i)], 0.0);  // upstream: none
}

// Blood circulating round a ring of three cells (an instant of circulation in a loop: no cell
// is upstream of the others, so the step sweeps them by Gauss-Seidel): each cell's backward
// Euler balance C+_i (V + q) = V C_i + q C+_(i-1), a 3 x 3 linear system solved here by
// hand, from C = (1, 0, 0). Every sweep starts from the step's own C, not the last sweep's
// (which would forget what the cells held: the fixed point then the mean of the inflows).
TEST(TracerTransport, CirculationRoundARingSolvesEachCellsBalanceFromTheStepsStart) {
  TransportGrid ring;
  for (int i = 0; i < 3; ++i) ring.add_cell(i, 1.0);
  for (int i = 0; i < 3; ++i) ring.add_face(i, (i + 1) % 3, i, 10e-6);
  const double volume = 1e-13, q = 0.5e-13;
  RedCellTransport cells(ring, std::vector<double>(3, volume), 0.45, RedCellOptions{false, 1});
  TracerTransport tracer(3, 0, TracerCarrier::blood);
  tracer.restore(std::vector<double>{1, 0, 0}, {}, {}, {}, 0, 0);
  cells.step(std::vector<double>(3, q), {});
  ASSERT_EQ(cells.order().cyclic, 3u);
  tracer.step(cells, {}, {});
  // a = V / (V + q), b = q / (V + q): C0 = a + b C2, C1 = b C0, C2 = b C1 = b^2 C0.
  const double a = volume / (volume + q), b = q / (volume + q);
  const double c0 = a / (1 - b * b * b), c1 = b * c0, c2 = b * c1;
  EXPECT_NEAR(tracer.concentration()[0], c0, 1e-14);
  EXPECT_NEAR(tracer.concentration()[1], c1, 1e-14);
  EXPECT_NEAR(tracer.concentration()[2], c2, 1e-14);
  EXPECT_NEAR(tracer.amount(cells), volume, 1e-27);  // a closed ring keeps what it holds
}

TEST(IndicatorCurves, LandmarksOfKnownCurves) {
  // A triangle from 1 to 3 s peaking at 2 s (height 1), after a bolus centred at 0.5 s.
  IndicatorCurves bolus(1, 1.0, 0.5, false);
  for (int s = 0; s < 400; ++s) {
    const double t0 = s * 0.01, t1 = t0 + 0.01, tm = 0.5 * (t0 + t1);
    bolus.add(0, t0, t1, std::max(0.0, 1 - std::abs(tm - 2)));
  }
  const auto b = bolus.landmarks(4.0);
  EXPECT_NEAR(b.mean_transit[0], 1.5, 1e-12);  // centre of mass 2 s, less 0.5 s
  EXPECT_NEAR(b.peak[0], 0.995, 1e-12);        // the step centred nearest the apex
  EXPECT_NEAR(b.peak_time[0], 2.0, 0.01 + 1e-12);
  EXPECT_NEAR(b.arrival[0], 1.01, 0.01);       // 1 % of the injected 1
  // A step rising linearly from 1 s to 3 s to 0.5: mean delay 2 s after its start at 0.
  IndicatorCurves step(1, 1.0, 0.0, true);
  for (int s = 0; s < 600; ++s) {
    const double t0 = s * 0.01, t1 = t0 + 0.01, tm = 0.5 * (t0 + t1);
    step.add(0, t0, t1, 0.5 * std::clamp(tm - 1, 0.0, 2.0) / 2);
  }
  EXPECT_NEAR(step.landmarks(6.0).mean_transit[0], 2.0, 1e-9);
  // No indicator: nothing to report.
  IndicatorCurves none(1, 1.0, 0.0, false);
  none.add(0, 0, 1, 0);
  EXPECT_TRUE(std::isnan(none.landmarks(1).mean_transit[0]));
  EXPECT_TRUE(std::isnan(none.landmarks(1).arrival[0]));
}

}  // namespace
}  // namespace hemotree
