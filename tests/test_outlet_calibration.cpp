// Outlets stand exactly for what pruning removed.
#include <cmath>

#include <gtest/gtest.h>

#include "cli/setting_words.hpp"
#include "formats/network_io.hpp"
#include "formats/topology.hpp"
#include "generator/growth_rules.hpp"
#include "generator/tree_growth.hpp"
#include "physics/wall_law.hpp"
#include "pruner/outlet_calibration.hpp"
#include "pruner/pruning_strategies.hpp"
#include "tests/grown_trees.hpp"
#include "steady/steady_flow.hpp"

using namespace hemotree;

namespace {

Network full_tree() {
  Network net = test_networks::grown_tree(400e-6, 8.5e-6, 11);
  net.blood = Blood{};
  Inlet inlet;
  inlet.vessel = 0;
  inlet.waveform.mean = 0.05e-6 / 60;  // 0.05 ml/min into a 400 um artery
  net.inlet = inlet;
  return net;
}

}  // namespace

TEST(OutletCalibration, CapillaryResistanceGivesTheMeanDropExactly) {
  Network full = full_tree();
  KeepMask keep(full.vessel_count(), 1);
  Network pruned = extract(full, keep);
  const OutletParameters p;
  const OutletReport report = calibrate_outlets(full, keep, pruned, p);
  const SteadyFlow s = solve_steady_flow(full);
  double drop = 0;
  for (const Outlet& o : full.outlets) drop += s.flow[o.vessel] * o.r;
  EXPECT_NEAR(drop / static_cast<double>(full.outlets.size()), p.capillary_pressure_drop, 1e-9);
  EXPECT_EQ(report.leaf, full.outlets.size());
}

TEST(OutletCalibration, PrunedNetworkReproducesTheFullTreesInletPressure) {
  for (int max_generation : {2, 5, 9}) {
    Network full = full_tree();
    const KeepMask keep = prune_by_generation(full, max_generation);
    Network pruned = extract(full, keep);
    const OutletReport report = calibrate_outlets(full, keep, pruned, OutletParameters{});
    EXPECT_NEAR(report.steady_inlet_pressure_pruned / report.steady_inlet_pressure_full, 1.0, 1e-12);
    // And the flow into each terminal vessel is the flow the full tree sends there.
    const SteadyFlow fs = solve_steady_flow(full), ps = solve_steady_flow(pruned);
    std::size_t k = 0;
    for (std::size_t v = 0; v < full.vessel_count(); ++v) {
      if (!keep[v]) continue;
      EXPECT_NEAR(ps.flow[k++], fs.flow[v], 1e-9 * fs.flow[0]);
    }
  }
}

TEST(OutletCalibration, OutletTypesFollowTheDiameterAndRcrMatchesTheImpedance) {
  Network full = full_tree();
  const KeepMask keep = prune_by_generation(full, 6);
  Network pruned = extract(full, keep);
  const OutletParameters p;
  calibrate_outlets(full, keep, pruned, p);
  const Children children = children_of(pruned);
  std::size_t terminals = 0;
  for (std::size_t v = 0; v < pruned.vessel_count(); ++v)
    terminals += children.offset[v] == children.offset[v + 1];
  ASSERT_EQ(pruned.outlets.size(), terminals);
  std::size_t rcr = 0;
  for (const Outlet& o : pruned.outlets) {
    const double d = pruned.diameter[o.vessel];
    EXPECT_DOUBLE_EQ(o.p_out, p.venous_pressure);
    if (o.type == BoundaryType::rcr) {
      ++rcr;
      EXPECT_GE(d, 100e-6);
      TubeLaw law = tube_law({d, pruned.wall_thickness[o.vessel], pruned.youngs_modulus[o.vessel]},
                             p.external_pressure);
      law.density = 1050;
      const double a = law.reference_area;
      EXPECT_NEAR(o.r1, 1050 * law.wave_speed(a) / a, 1e-9 * o.r1);
      EXPECT_GT(o.r2, 0);
      EXPECT_GT(o.c, 0);
    } else {
      EXPECT_EQ(o.type, BoundaryType::resistance);
    }
  }
  EXPECT_GT(rcr, 0u);
}

TEST(OutletCalibration, CompliancesSumTheRemovedVessels) {
  // Keep only the root: its RCR's C is the compliance of every other vessel.
  Network full = full_tree();
  KeepMask keep(full.vessel_count(), 0);
  keep[0] = 1;
  Network pruned = extract(full, keep);
  const OutletParameters p;
  calibrate_outlets(full, keep, pruned, p);
  double c = 0;
  for (std::size_t v = 1; v < full.vessel_count(); ++v) {
    const TubeLaw law = tube_law({full.diameter[v], full.wall_thickness[v], full.youngs_modulus[v]},
                                 p.external_pressure);
    c += 2 * full.length[v] * std::sqrt(law.reference_area) / law.beta;
  }
  ASSERT_EQ(pruned.outlets.size(), 1u);
  EXPECT_NEAR(pruned.outlets[0].c, c, 1e-9 * c);
}

TEST(OutletCalibration, OutletsInletAndBloodSurviveTheFile) {
  Network full = full_tree();
  const KeepMask keep = prune_by_generation(full, 4);
  Network pruned = extract(full, keep);
  calibrate_outlets(full, keep, pruned, OutletParameters{});
  const char* path = "/tmp/hemotree-test-outlets.json";
  {
    OutputStream out(path);
    write_network(pruned, out);
    out.commit();
  }
  const Network back = read_network(path);
  std::remove(path);
  ASSERT_EQ(back.outlets.size(), pruned.outlets.size());
  for (std::size_t k = 0; k < back.outlets.size(); ++k) {
    EXPECT_EQ(back.outlets[k].vessel, pruned.outlets[k].vessel);
    EXPECT_EQ(back.outlets[k].type, pruned.outlets[k].type);
    EXPECT_NEAR(back.outlets[k].resistance(), pruned.outlets[k].resistance(),
                1e-12 * pruned.outlets[k].resistance());
  }
  ASSERT_TRUE(back.inlet && back.blood);
  EXPECT_DOUBLE_EQ(back.inlet->waveform.mean, pruned.inlet->waveform.mean);
  EXPECT_NEAR(solve_steady_flow(back).inlet_pressure, solve_steady_flow(pruned).inlet_pressure,
              1e-9 * solve_steady_flow(pruned).inlet_pressure);
}

// vprune's default inflow (1.74 ml/min, meant for the 1 mm tree) on a 60 um tree gave a
// steady inlet pressure of 81,142 mmHg without a word.
TEST(OutletCalibration, AnUnphysiologicalPressureIsNamedWithItsLikelyCauseAndRemedy) {
  auto calibrated = [](double mean_flow) {
    GrowthParameters g;
    g.root_diameter = 60e-6;
    g.seed = 1;
    Network full = grow_tree(default_rules(), g);
    full.blood = Blood{};
    Inlet inlet;
    inlet.vessel = 0;
    inlet.waveform.mean = mean_flow;
    full.inlet = inlet;
    const KeepMask keep = prune_by_generation(full, 3);
    Network pruned = extract(full, keep);
    return calibrate_outlets(full, keep, pruned, OutletParameters{});
  };
  const double default_flow = 1.74e-6 / 60;
  const OutletReport report = calibrated(default_flow);
  EXPECT_NEAR(report.steady_inlet_pressure_full / 133.322, 81142.2, 0.5);
  const std::string warning =
      unphysiological_pressure_warning(report, OutletParameters{}, default_flow, 60e-6, vprune_words());
  EXPECT_NE(warning.find("81142.2 mmHg"), std::string::npos) << warning;
  EXPECT_NE(warning.find("--mean-flow (1.74 ml/min) is likely too large"), std::string::npos) << warning;
  EXPECT_NE(warning.find("60 um"), std::string::npos) << warning;
  // The flow it suggests gives about 100 mmHg: the drop down the tree is Poiseuille, linear in
  // the flow, but the capillary outlets' R_cap = drop x leaves / Q follows the flow, which
  // shifts its split among the leaves a little (101.4 mmHg here).
  const auto at = warning.find("(about ");
  ASSERT_NE(at, std::string::npos) << warning;
  const double suggested_ml_min = std::stod(warning.substr(at + 7));
  const OutletReport remedied = calibrated(suggested_ml_min * 1e-6 / 60);
  EXPECT_NEAR(remedied.steady_inlet_pressure_full / 133.322, 100.0, 2.0);
  EXPECT_EQ(unphysiological_pressure_warning(remedied, OutletParameters{}, suggested_ml_min * 1e-6 / 60,
                                             60e-6),
            "");
  // A negative pressure comes from the venous pressure, not the flow.
  OutletParameters negative;
  negative.venous_pressure = -50 * 133.322;
  OutletReport low = remedied;
  low.steady_inlet_pressure_full = -20 * 133.322;
  EXPECT_NE(unphysiological_pressure_warning(low, negative, 1e-9, 60e-6, vprune_words()).find("--venous-pressure (-50 mmHg)"),
            std::string::npos);
  // Without a tool's words, the settings' own names.
  EXPECT_NE(unphysiological_pressure_warning(low, negative, 1e-9, 60e-6).find(": venous_pressure (-50 mmHg)"),
            std::string::npos);
}
