// The red-cell transport scheme on its own, fed with flows whose answer is known: a step and
// a bolus through a vessel whose flow oscillates and reverses (bounds, conservation, no
// oscillation), a compliant vessel (cell volumes that breathe), a bifurcation against the
// Pries-Secomb law, a loop whose flow circulates and reverses over many cycles, and the memory
// a tree's red cells and a tracer hold.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "core/errors.hpp"
#include "physics/phase_separation.hpp"
#include "tests/transport_grids.hpp"
#include "transport/red_cell_transport.hpp"
#include "transport/tracer_transport.hpp"

namespace hemotree {
namespace {

using namespace test_grids;
constexpr double nan = std::numeric_limits<double>::quiet_NaN();

// The red cells unaccounted for, relative to all that passed: round-off, summed over the
// steps (a thousand steps of sums of a few terms each leave some 1e-14).
double balance_error(const RedCellTransport& t, double initial) {
  return std::abs(t.red_cells() - initial - (t.entered() - t.left())) / (initial + t.entered() + t.left());
}

TEST(RedCellTransport, StepThroughOscillatingReversingFlowStaysBoundedAndConserved) {
  const int n = 40;
  const double volume = 1e-12, hd0 = 0.2, hd_in = 0.45;
  RedCellTransport t(vessel(n), std::vector<double>(n, volume), hd0);
  const double initial = t.red_cells();
  const std::vector<double> inflow{hd_in, nan};  // backflow at the end returns what left there
  // Q(t) = Qm (0.3 + sin w t): forward on average, backward a third of each cycle, up to 2.6
  // slices a step (an implicit scheme: no Courant limit).
  const int steps_per_cycle = 50;
  double max_seen = 0, min_seen = 1;
  for (int cycle = 0; cycle < 60; ++cycle)
    for (int s = 0; s < steps_per_cycle; ++s) {
      const double phase = 2 * std::numbers::pi * (s + 0.5) / steps_per_cycle;
      t.step(along(n, 2 * volume * (0.3 + std::sin(phase))), inflow);
      for (const double h : t.discharge_hematocrit()) {
        max_seen = std::max(max_seen, h);
        min_seen = std::min(min_seen, h);
      }
      ASSERT_LT(balance_error(t, initial), 1e-13);
    }
  // No new extrema: every value lies between the initial 0.2 and the inflow 0.45.
  EXPECT_GE(min_seen, hd0 - 1e-15);
  EXPECT_LE(max_seen, hd_in + 1e-15);
  // The net forward flow has replaced the vessel's blood: inflow hematocrit everywhere.
  for (const double h : t.discharge_hematocrit()) EXPECT_NEAR(h, hd_in, 1e-9);
}

TEST(RedCellTransport, FrontHasNoOscillationAndMovesAtTheFlowSpeed) {
  const int n = 100;
  const double volume = 1e-12;
  RedCellTransport t(vessel(n), std::vector<double>(n, volume), 0.0);
  const std::vector<double> inflow{0.4, nan};
  // 40 steps at a Courant number of 0.5 move the blood 20 slices.
  for (int s = 0; s < 40; ++s) {
    t.step(along(n, 0.5 * volume), inflow);
    const auto h = t.discharge_hematocrit();
    for (int i = 0; i + 1 < n; ++i) ASSERT_GE(h[i] + 1e-16, h[i + 1]) << "step " << s << " slice " << i;
  }
  // The front's centre (where the profile crosses half the inflow) near slice 20: the red
  // cells in the vessel are the inflow's, 20 slices' worth.
  EXPECT_NEAR(t.red_cells() / (0.4 * volume), 20.0, 1e-9);
  const auto h = t.discharge_hematocrit();
  const int half = static_cast<int>(std::find_if(h.begin(), h.end(), [](double x) { return x < 0.2; }) - h.begin());
  EXPECT_NEAR(half, 20, 3);
}

TEST(RedCellTransport, BolusInReversingFlowKeepsItsCellsAndBounds) {
  const int n = 60;
  const double volume = 1e-12;
  RedCellTransport t(vessel(n), std::vector<double>(n, volume), 0.3);
  std::vector<double> h(n, 0.3);
  for (int i = 20; i < 30; ++i) h[static_cast<std::size_t>(i)] = 0.6;  // the bolus
  t.set_hematocrit(h);
  const double initial = t.red_cells();
  const std::vector<double> inflow{0.3, 0.3};
  // Pure oscillation (no net flow), 13 slices back and forth: the bolus sloshes and spreads
  // (the scheme's numerical diffusion) and in time reaches the ends.
  for (int s = 0; s < 2000; ++s) {
    const double q = volume * std::sin(2 * std::numbers::pi * (s + 0.5) / 40);
    t.step(along(n, q), inflow);
    for (const double x : t.discharge_hematocrit()) {
      ASSERT_GE(x, 0.3 - 1e-15);
      ASSERT_LE(x, 0.6 + 1e-15);
    }
    ASSERT_LT(balance_error(t, initial), 1e-13);
  }
  EXPECT_GT(t.red_cells(), 0.3 * n * volume);  // some of the bolus is still there
}

TEST(RedCellTransport, CompliantVesselConservesAndStaysBelowOne) {
  // Faces pass different volumes: the slices fill and empty (V changes by up to half).
  const int n = 20;
  const double volume = 1e-12;
  RedCellTransport t(vessel(n, fahraeus_parameter(8e-6)), std::vector<double>(n, volume), 0.45);
  const double initial = t.red_cells();
  const std::vector<double> inflow{0.9, nan};
  for (int s = 0; s < 4000; ++s) {
    const double phase = 2 * std::numbers::pi * (s + 0.5) / 100;
    std::vector<double> q(n + 1);
    for (int i = 0; i <= n; ++i)
      q[static_cast<std::size_t>(i)] = volume * (0.2 + std::sin(phase) + 0.02 * std::cos(phase) * (i - n / 2.0));
    q[0] = -q[0];
    t.step(q, inflow);
    for (const double v : t.volume()) ASSERT_GT(v, 0);
    for (const double x : t.discharge_hematocrit()) {
      ASSERT_GE(x, 0);
      ASSERT_LT(x, 1);
    }
    ASSERT_LT(balance_error(t, initial), 1e-13);
  }
}

TEST(RedCellTransport, UniformHematocritStaysUniformWithTheFahraeusEffect) {
  // In a rigid vessel the tube hematocrit differs from the discharge one, yet a uniform
  // discharge hematocrit fed at the same value is a steady state of the scheme.
  const int n = 10;
  RedCellTransport t(vessel(n, fahraeus_parameter(6e-6)), std::vector<double>(n, 1e-12), 0.45);
  for (int s = 0; s < 100; ++s) t.step(along(n, 0.7e-12 * std::sin(0.3 * s)), std::vector<double>{0.45, 0.45});
  for (const double h : t.discharge_hematocrit()) EXPECT_NEAR(h, 0.45, 1e-14);
  EXPECT_NEAR(t.tube_hematocrit(0), tube_hematocrit(0.45, 6e-6), 1e-15);
  EXPECT_LT(t.tube_hematocrit(0), 0.45 * 0.8);  // a 6 um tube holds much less than it passes
}

// A feed of slices into a bifurcation node (no volume) and two daughters to outlets.
struct Bifurcating {
  TransportGrid grid;
  std::int32_t node, first, second;  // the node cell, the daughters' first slices
  std::vector<double> faces(double feed, double fraction) const {
    // faces: inlet(0), feed slices(1..3), node->d1(4), d1 slices(5,6), d1 outlet(7), node->d2(8), ...
    std::vector<double> q(grid.face_count());
    q[0] = -feed;
    for (int i = 1; i <= 3; ++i) q[static_cast<std::size_t>(i)] = feed;
    for (int i = 4; i <= 7; ++i) q[static_cast<std::size_t>(i)] = feed * fraction;
    for (int i = 8; i <= 11; ++i) q[static_cast<std::size_t>(i)] = feed * (1 - fraction);
    return q;
  }
};

Bifurcating bifurcation(double feed_d, double d1, double d2) {
  Bifurcating b;
  TransportGrid& g = b.grid;
  g.boundaries = 3;
  for (int i = 0; i < 3; ++i) g.add_cell(-1, 1);
  b.node = 3;
  g.add_cell(7, 1);
  b.first = 4;
  for (int i = 0; i < 3; ++i) g.add_cell(-1, 1);
  b.second = 7;
  for (int i = 0; i < 3; ++i) g.add_cell(-1, 1);
  g.add_face(0, TransportGrid::boundary_side(0), 0, feed_d);
  g.add_face(0, 1, 0, feed_d);
  g.add_face(1, 2, 0, feed_d);
  g.add_face(2, b.node, 0, feed_d);
  g.add_face(b.node, 4, 1, d1);
  g.add_face(4, 5, 1, d1);
  g.add_face(5, 6, 1, d1);
  g.add_face(6, TransportGrid::boundary_side(1), 1, d1);
  g.add_face(b.node, 7, 2, d2);
  g.add_face(7, 8, 2, d2);
  g.add_face(8, 9, 2, d2);
  g.add_face(9, TransportGrid::boundary_side(2), 2, d2);
  return b;
}

TEST(RedCellTransport, BifurcationSplitsAsThePriesSecombLaw) {
  const Bifurcating b = bifurcation(12e-6, 10e-6, 7e-6);
  std::vector<double> volume(b.grid.cell_count(), 1e-13);
  volume[static_cast<std::size_t>(b.node)] = 0;
  RedCellTransport t(b.grid, volume, 0.45);
  const std::vector<double> inflow{0.45, nan, nan};
  for (const double fraction : {0.3, 0.62, 0.9}) {
    for (int s = 0; s < 5000; ++s) t.step(b.faces(2e-14, fraction), inflow);
    Bifurcation law;
    law.feed_diameter = 12e-6;
    law.first_diameter = 10e-6;
    law.second_diameter = 7e-6;
    law.flow_fraction = fraction;
    law.feed_hematocrit = 0.45;
    const DaughterHematocrits expected = daughter_hematocrits(law);
    const auto h = t.discharge_hematocrit();
    EXPECT_NEAR(h[static_cast<std::size_t>(b.first) + 2], expected.first, 1e-12) << fraction;
    EXPECT_NEAR(h[static_cast<std::size_t>(b.second) + 2], expected.second, 1e-12) << fraction;
    EXPECT_EQ(t.separating_nodes(), 1u);
  }
  // Without phase separation both daughters carry the feed's hematocrit.
  RedCellTransport mixed(b.grid, volume, 0.45, RedCellOptions{false, 1});
  for (int s = 0; s < 400; ++s) mixed.step(b.faces(2e-14, 0.2), inflow);
  EXPECT_NEAR(mixed.discharge_hematocrit()[static_cast<std::size_t>(b.first) + 2], 0.45, 1e-12);
  EXPECT_NEAR(mixed.discharge_hematocrit()[static_cast<std::size_t>(b.second) + 2], 0.45, 1e-12);
}

// hostile-inputs 00: a closed end passes round-off flows (1e-27 against 1e-7), so that the
// flow fraction q1 / (q1 + q2) is 1 exactly; the daughters' shares once divided by 1 - that,
// and the 0 / 0 put NaN into the run (and the Pries law then aborted it).
TEST(RedCellTransport, DaughterOfRoundOffFlowKeepsFiniteHematocrits) {
  const Bifurcating b = bifurcation(12e-6, 10e-6, 7e-6);
  std::vector<double> volume(b.grid.cell_count(), 1e-13);
  volume[static_cast<std::size_t>(b.node)] = 0;
  RedCellTransport t(b.grid, volume, 0.45);
  const std::vector<double> inflow{0.45, nan, nan};
  for (const double round_off : {1e-31, -1e-31}) {  // into the closed branch, and back out of it
    std::vector<double> q = b.faces(2e-14, 1.0);
    for (int i = 8; i <= 10; ++i) q[static_cast<std::size_t>(i)] = round_off;
    q[11] = 0;
    for (int s = 0; s < 50; ++s) t.step(q, inflow);
    for (const double h : t.discharge_hematocrit()) {
      EXPECT_TRUE(h >= 0 && h < 1) << h;
    }
  }
  // The main daughter carries what the feed brings.
  EXPECT_NEAR(t.discharge_hematocrit()[static_cast<std::size_t>(b.first) + 2], 0.45, 1e-9);
}

TEST(RedCellTransport, LoopWithCirculatingReversingFlowOverManyCycles) {
  // Two paths of 5 slices between nodes A and B, fed through a slice from an inlet and
  // drained through one to an outlet, with a circulation around the loop that reverses each
  // cycle: at times A feeds both paths (phase separation), at times the loop runs one way
  // round (a directed cycle: the Gauss-Seidel part).
  TransportGrid g;
  g.boundaries = 2;
  const std::int32_t a = 0, b = 1, feed = 12, drain = 13;
  g.add_cell(100, 1);
  g.add_cell(101, 1);
  for (int i = 0; i < 10; ++i) g.add_cell(-1, fahraeus_parameter(9e-6));
  g.add_cell(-1, 1);
  g.add_cell(-1, 1);
  g.add_face(feed, TransportGrid::boundary_side(0), 2, 15e-6);  // inlet (faces 0..3)
  g.add_face(feed, a, 2, 15e-6);
  g.add_face(b, drain, 3, 15e-6);
  g.add_face(drain, TransportGrid::boundary_side(1), 3, 15e-6);  // outlet
  for (int p = 0; p < 2; ++p) {  // path p: faces 4 + 6 p .. 9 + 6 p
    const std::int32_t first = 2 + 5 * p;
    const double d = 9e-6 + p * 3e-6;
    g.add_face(a, first, p, d);
    for (int i = 0; i < 4; ++i) g.add_face(first + i, first + i + 1, p, d);
    g.add_face(first + 4, b, p, d);
  }
  std::vector<double> volume(14, 1e-13);
  volume[0] = volume[1] = 0;  // the nodes are junctions
  RedCellTransport t(g, volume, 0.3);
  const double initial = t.red_cells();
  const std::vector<double> inflow{0.5, nan};
  std::size_t cyclic_steps = 0, separating_steps = 0;
  for (int s = 0; s < 20000; ++s) {
    const double phase = 2 * std::numbers::pi * (s + 0.5) / 200;
    const double through = 2e-14 * (1 + 0.8 * std::sin(phase));  // in at A, out at B
    const double circulation = 3e-14 * std::cos(phase);          // along path 1, back along path 2
    std::vector<double> q(g.face_count());
    q[0] = -through;
    q[1] = q[2] = q[3] = through;
    for (std::size_t f = 4; f < 10; ++f) q[f] = 0.5 * through + circulation;
    for (std::size_t f = 10; f < 16; ++f) q[f] = 0.5 * through - circulation;
    t.step(q, inflow);
    cyclic_steps += t.order().cyclic > 0;
    separating_steps += t.separating_nodes() > 0;
    for (const double h : t.discharge_hematocrit()) {
      ASSERT_GE(h, 0);
      ASSERT_LT(h, 1);
    }
    ASSERT_LT(balance_error(t, initial), 1e-13);
  }
  EXPECT_GT(cyclic_steps, 0u);
  EXPECT_GT(separating_steps, 0u);
  // Over the last cycles what leaves matches what enters (0.5 of the inflow), in the mean.
  EXPECT_NEAR(t.left() / t.entered(), 1.0, 0.01);
}

// The memory a tree's red cells and a tracer hold (docs/transport.md, "Memory"), counted as
// the arrays' capacities: a binary tree of 0D vessels, a cell a node and a face a vessel, a
// boundary face at the root and at each leaf (so about 1 cell, 1.5 faces and 0.5 boundaries
// a vessel). What the design allows a vessel: the grid 42 B (a cell's node and Fahraeus
// parameter 12 B, a face's sides, vessel and diameter 20 B), each cell's faces 14 B, the flow
// order 9.5 B; the state and a step's arrays 84 B (per cell the volume, the next volume, the
// hematocrit and the red cells before a step; per face the share, the blood and the red
// cells through it; per boundary three numbers; the nodes where the law may split and those
// where it did, 2 B each):
// 149.5 B, and a tracer's 20 B (a concentration a cell, three numbers a boundary). A new
// array of a double a face adds 12 B and fails this.
TEST(RedCellTransport, ATreeHoldsItsGridStateAndOneStepsArraysAlone) {
  const int depth = 14, vessels = (1 << depth) - 1, leaves = 1 << (depth - 1);
  TransportGrid g;
  g.boundaries = static_cast<std::size_t>(leaves) + 1;
  for (int c = 0; c <= vessels; ++c) g.add_cell(c, 0.9);  // cell 0 above the root vessel
  for (int v = 1; v <= vessels; ++v) g.add_face(v / 2, v, v - 1, 10e-6);  // vessel v - 1 into node v
  g.add_face(0, TransportGrid::boundary_side(0), -1, 0.0);  // the inlet (flow in: negative)
  for (int leaf = 0; leaf < leaves; ++leaf) g.add_face(leaves + leaf, TransportGrid::boundary_side(1 + static_cast<std::size_t>(leaf)), -1, 0.0);
  std::vector<double> faces(g.face_count());
  for (int v = 1; v <= vessels; ++v) faces[static_cast<std::size_t>(v - 1)] = 1e-14 / (1 << static_cast<int>(std::log2(v)));
  faces[static_cast<std::size_t>(vessels)] = -1e-14;
  for (int leaf = 0; leaf < leaves; ++leaf) faces[static_cast<std::size_t>(vessels + 1 + leaf)] = 1e-14 / leaves;
  RedCellTransport t(g, std::vector<double>(static_cast<std::size_t>(vessels) + 1, 1e-13), 0.45);
  TracerTransport dye(t.grid().cell_count(), t.grid().boundaries, TracerCarrier::plasma);
  std::vector<double> inflow(t.grid().boundaries, nan), dye_in(t.grid().boundaries, nan);
  inflow[0] = 0.45;
  dye_in[0] = 1;
  for (int s = 0; s < 3; ++s) {
    t.step(faces, inflow);
    dye.step(t, dye_in, Injection{});
  }
  EXPECT_GT(t.separating_nodes(), 0u);
  EXPECT_GT(dye.concentration()[1], 0);
  EXPECT_LE(static_cast<double>(t.bytes()) / vessels, 149.5 + 0.5) << t.bytes();
  EXPECT_LE(static_cast<double>(dye.bytes()) / vessels, 20 + 0.5) << dye.bytes();
}

TEST(RedCellTransport, RefusesWhatItCannotRepresent) {
  EXPECT_THROW(RedCellTransport(vessel(3), std::vector<double>(2, 1e-12), 0.4), InputError);
  EXPECT_THROW(RedCellTransport(vessel(3), std::vector<double>{1e-12, -1e-12, 1e-12}, 0.4), InputError);
  EXPECT_THROW(RedCellTransport(vessel(3), std::vector<double>(3, 1e-12), 1.0), InputError);
  RedCellTransport t(vessel(3), std::vector<double>(3, 1e-12), 0.4);
  EXPECT_THROW(t.step(std::vector<double>(3, 0.0), std::vector<double>{0.4, 0.4}), InputError);
  EXPECT_THROW(t.set_hematocrit(std::vector<double>{0.4, 1.2, 0.4}), InputError);
}

}  // namespace
}  // namespace hemotree
