// A grid cut in two as a run over ranks cuts it (transport/transport_grid.hpp's cuts,
// docs/transport.md "Over MPI ranks"): a top of two node cells and a share of four below its
// two roots, stepped in parts with the two messages between them played here, against the
// whole grid stepped at once. Flows that turn round, daughters of opposite signs (a root node
// that feeds its parent and a daughter: phase separation sent up), every cell's hematocrit
// and every boundary's red cells equal to the bit; a tracer on the plasma the same, injected
// into a root vessel (which the share, the vessel's rank, injects).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "transport/red_cell_transport.hpp"
#include "transport/tracer_transport.hpp"

namespace hemotree {
namespace {

constexpr double nan = std::numeric_limits<double>::quiet_NaN();
constexpr double um = 1e-6;

// The whole tree: inlet boundary 0 -> T0 -> T1, which divides into S2 (whose daughters S4, S5
// leave through boundaries 1, 2) and S3 (boundary 3). Faces in the order a run makes them:
// vessels 0 (T0 T1), 1 (T1 S2), 2 (T1 S3), 3 (S2 S4), 4 (S2 S5), then the boundaries.
TransportGrid whole_tree() {
  TransportGrid g;
  g.boundaries = 4;
  for (int c = 0; c < 6; ++c) g.add_cell(c, 0.8);
  g.add_face(0, 1, 0, 30 * um);
  g.add_face(1, 2, 1, 20 * um);
  g.add_face(1, 3, 2, 15 * um);
  g.add_face(2, 4, 3, 12 * um);
  g.add_face(2, 5, 4, 9 * um);
  g.add_face(0, TransportGrid::boundary_side(0), -1, 0);
  g.add_face(4, TransportGrid::boundary_side(1), -1, 0);
  g.add_face(5, TransportGrid::boundary_side(2), -1, 0);
  g.add_face(3, TransportGrid::boundary_side(3), -1, 0);
  return g;
}

// The top's side: T0, T1; vessels 1 and 2 go to cuts 4 and 5.
TransportGrid top_side() {
  TransportGrid g;
  g.boundaries = 6;
  g.cuts = 2;
  g.add_cell(0, 0.8);
  g.add_cell(1, 0.8);
  g.add_face(0, 1, 0, 30 * um);
  g.add_face(1, TransportGrid::boundary_side(4), 1, 20 * um);
  g.add_face(1, TransportGrid::boundary_side(5), 2, 15 * um);
  g.add_face(0, TransportGrid::boundary_side(0), -1, 0);
  return g;
}

// The share's side: S2, S3, S4, S5 (its cells 0 to 3); vessels 1 and 2 from cuts 4 and 5,
// turned round (their node here is their `to` node).
TransportGrid share_side() {
  TransportGrid g;
  g.boundaries = 6;
  g.cuts = 2;
  for (int c = 2; c < 6; ++c) g.add_cell(c, 0.8);
  g.add_face(0, TransportGrid::boundary_side(4), 1, 20 * um);
  g.add_face(1, TransportGrid::boundary_side(5), 2, 15 * um);
  g.add_face(0, 2, 3, 12 * um);
  g.add_face(0, 3, 4, 9 * um);
  g.add_face(2, TransportGrid::boundary_side(1), -1, 0);
  g.add_face(3, TransportGrid::boundary_side(2), -1, 0);
  g.add_face(1, TransportGrid::boundary_side(3), -1, 0);
  return g;
}

// Step s's volumes (cells of volume v), which keep every cell's: S2's daughters of their own
// phases (at times S4 feeds S2, which sends to T1 and S5), S3's outflow, the parents' sums;
// each side's faces as it has them.
struct StepVolumes {
  std::vector<double> whole, top, share;
  bool up_through_root = false, up_through_cut = false;  // vessel 1 up; vessel 1 or 2 up
};
StepVolumes step_volumes(int s, double v) {
  const double t = 2 * std::numbers::pi * s / 100;
  const double q3 = 0.2 * v * (0.2 + std::sin(t)), q4 = 0.15 * v * (0.5 + std::cos(1.3 * t));
  const double q8 = 0.1 * v * (0.4 + std::sin(0.7 * t + 1)), q1 = q3 + q4, q2 = q8, q0 = q1 + q2;
  return {{q0, q1, q2, q3, q4, -q0, q3, q4, q8}, {q0, q1, q2, -q0}, {-q1, -q2, q3, q4, q3, q4, q8}, q1 < 0, q1 < 0 || q2 < 0};
}

// The red cells' step on both sides, their two messages played here: each root node's H_D and
// its face's share up (the top takes s H_D as its cuts' inflow), T1's through each of its cut
// faces down.
void step_both_sides(RedCellTransport& top, RedCellTransport& share, const StepVolumes& q,
                     const std::vector<double>& inflow) {
  using Cells = RedCellTransport::Cells;
  top.begin_step(q.top);
  share.begin_step(q.share);
  top.solve(q.top, inflow, Cells::before_cuts);
  share.solve(q.share, inflow, Cells::before_cuts);
  std::vector<double> top_inflow = inflow, share_inflow = inflow;
  for (int j = 0; j < 2; ++j) top_inflow[4 + j] = share.separation_share(j) * share.discharge_hematocrit()[j];
  top.solve(q.top, top_inflow, Cells::after_cuts);
  for (int j = 0; j < 2; ++j) share_inflow[4 + j] = top.separation_share(1 + j) * top.discharge_hematocrit()[1];
  share.solve(q.share, share_inflow, Cells::after_cuts);
  top.end_step(q.top, top_inflow);
  share.end_step(q.share, share_inflow);
}

TEST(RedCellCut, TwoSidesStepInPartsToTheWholeGridsBits) {
  const double v = 1e-13, h0 = 0.45;
  RedCellTransport whole(whole_tree(), std::vector<double>(6, v), h0);
  RedCellTransport top(top_side(), std::vector<double>(2, v), h0);
  RedCellTransport share(share_side(), std::vector<double>(4, v), h0);
  std::vector<double> inflow(4, nan), cut_inflow(6, nan);
  inflow[0] = cut_inflow[0] = 0.4;  // the inlet's; the outlets return what left them
  int separated = 0, up_through_cut = 0;
  for (int s = 0; s < 400; ++s) {
    const StepVolumes q = step_volumes(s, v);
    up_through_cut += q.up_through_cut;
    whole.step(q.whole, inflow);
    step_both_sides(top, share, q, cut_inflow);

    separated += whole.separating_nodes() > 0;
    for (int c = 0; c < 2; ++c) ASSERT_EQ(top.discharge_hematocrit()[c], whole.discharge_hematocrit()[c]) << "step " << s;
    for (int c = 0; c < 4; ++c)
      ASSERT_EQ(share.discharge_hematocrit()[c], whole.discharge_hematocrit()[2 + c]) << "step " << s << " cell S" << 2 + c;
  }
  // Both ways through the cuts, and the law splitting red cells at nodes, happened.
  EXPECT_GT(up_through_cut, 50);
  EXPECT_GT(separated, 50);
  // Each boundary's red cells in and out are the whole grid's, and none through a cut.
  EXPECT_EQ(top.entered_by_boundary()[0], whole.entered_by_boundary()[0]);
  for (int b = 1; b < 4; ++b) EXPECT_EQ(share.left_by_boundary()[b], whole.left_by_boundary()[b]);
  for (int b = 4; b < 6; ++b) {
    EXPECT_EQ(top.entered_by_boundary()[b] + top.left_by_boundary()[b], 0.0);
    EXPECT_EQ(share.entered_by_boundary()[b] + share.left_by_boundary()[b], 0.0);
  }
  // The red cells on both sides are the whole grid's, and its balance closes.
  EXPECT_NEAR(top.red_cells() + share.red_cells(), whole.red_cells(), 1e-15 * whole.red_cells());
  const double initial = 6 * v * h0 * (0.8 + 0.2 * h0);
  EXPECT_NEAR(whole.red_cells() - initial, whole.entered() - whole.left(), 1e-13 * initial);
}

TEST(RedCellCut, ATracerInjectedIntoARootVesselStepsInPartsToTheWholeGridsBits) {
  const double v = 1e-13, h0 = 0.45;
  RedCellTransport whole(whole_tree(), std::vector<double>(6, v), h0);
  RedCellTransport top(top_side(), std::vector<double>(2, v), h0);
  RedCellTransport share(share_side(), std::vector<double>(4, v), h0);
  TracerTransport whole_dye(6, 4, TracerCarrier::plasma), top_dye(2, 6, TracerCarrier::plasma),
      share_dye(4, 6, TracerCarrier::plasma);
  std::vector<double> inflow(4, nan), cut_inflow(6, nan);
  inflow[0] = cut_inflow[0] = 0.4;
  using Cells = RedCellTransport::Cells;
  int up_through_root = 0;
  for (int s = 0; s < 300; ++s) {
    const StepVolumes q = step_volumes(s, v);
    up_through_root += q.up_through_root;
    // The dye: at the inlet, and injected into vessel 1 (whole face 1, the share's face 0).
    const double given = 1 + 0.5 * std::sin(0.3 * 2 * std::numbers::pi * s / 100);
    std::vector<double> dye_in(4, nan), dye_cut_in(6, nan);
    dye_in[0] = dye_cut_in[0] = given;
    const Injection whole_injected{1, 0.5 * given}, share_injected{0, 0.5 * given};

    whole.step(q.whole, inflow);
    whole_dye.step(whole, dye_in, whole_injected);
    step_both_sides(top, share, q, cut_inflow);

    // The dye's two messages: what crosses each cut from either side.
    const Injection top_injected;
    top_dye.begin_step(top, dye_cut_in, top_injected);
    share_dye.begin_step(share, dye_cut_in, share_injected);
    top_dye.solve(top, dye_cut_in, top_injected, Cells::before_cuts);
    share_dye.solve(share, dye_cut_in, share_injected, Cells::before_cuts);
    std::vector<double> top_dye_in = dye_cut_in, share_dye_in = dye_cut_in;
    for (int j = 0; j < 2; ++j) top_dye_in[4 + j] = share_dye.inflowing(j, share, dye_cut_in, share_injected);
    top_dye.solve(top, top_dye_in, top_injected, Cells::after_cuts);
    for (int j = 0; j < 2; ++j) share_dye_in[4 + j] = top_dye.inflowing(1 + j, top, top_dye_in, top_injected);
    share_dye.solve(share, share_dye_in, share_injected, Cells::after_cuts);
    top_dye.end_step(top, top_dye_in, top_injected);
    share_dye.end_step(share, share_dye_in, share_injected);

    for (int c = 0; c < 2; ++c) ASSERT_EQ(top_dye.concentration()[c], whole_dye.concentration()[c]) << "step " << s;
    for (int c = 0; c < 4; ++c)
      ASSERT_EQ(share_dye.concentration()[c], whole_dye.concentration()[2 + c]) << "step " << s << " cell S" << 2 + c;
  }
  EXPECT_GT(up_through_root, 50);
  // The injection counted once, by the share; the inlet's and the outlets' dye the whole's.
  EXPECT_EQ(share_dye.injected(), whole_dye.injected());
  EXPECT_EQ(top_dye.injected(), 0.0);
  EXPECT_GT(whole_dye.injected(), 0.0);
  EXPECT_EQ(top_dye.entered_by_boundary()[0], whole_dye.entered_by_boundary()[0]);
  for (int b = 1; b < 4; ++b) EXPECT_EQ(share_dye.left_by_boundary()[b], whole_dye.left_by_boundary()[b]);
  // The whole grid's dye balance closes (no volume moved between steps: nothing adjusted).
  EXPECT_NEAR(whole_dye.amount(whole), whole_dye.entered() + whole_dye.injected() - whole_dye.left(),
              1e-13 * (whole_dye.entered() + whole_dye.injected()));
}

TEST(RedCellCut, ACellBelowACutWaitsForItsInflow) {
  // All of the share below the cuts while blood flows down: nothing of it is solved before
  // the cuts' inflow is given (its values stay), and all of it after.
  RedCellTransport share(share_side(), std::vector<double>(4, 1e-13), 0.3);
  const std::vector<double> q{-2e-14, -1e-14, 1e-14, 1e-14, 1e-14, 1e-14, 1e-14};
  std::vector<double> inflow(6, nan);
  share.begin_step(q);
  share.solve(q, inflow, RedCellTransport::Cells::before_cuts);
  for (const double h : share.discharge_hematocrit()) EXPECT_EQ(h, 0.3);
  inflow[4] = inflow[5] = 0.5;
  share.solve(q, inflow, RedCellTransport::Cells::after_cuts);
  share.end_step(q, inflow);
  for (const double h : share.discharge_hematocrit()) EXPECT_GT(h, 0.3);
}

}  // namespace
}  // namespace hemotree
