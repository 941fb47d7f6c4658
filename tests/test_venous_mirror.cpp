// vgen --venous: a tree and its venous mirror. With twins of the same size the network is
// antisymmetric about the capillaries: every twin carries its artery's flow, and every
// capillary end sits at the mean of the inflow and venous pressures (the arterial path to it
// and the venous path back have the same resistance) — an exact check of the looped steady
// solve on a network of thousands of loops.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "formats/network_io.hpp"
#include "generator/growth_rules.hpp"
#include "generator/tree_growth.hpp"
#include "generator/venous_mirror.hpp"
#include "steady/steady_flow.hpp"

using namespace hemotree;

TEST(VenousMirror, TwinsCarryTheirArteriesFlowAndCapillariesSitMidway) {
  GrowthParameters p;
  p.root_diameter = 120e-6;
  p.min_diameter = 8e-6;
  Network net = grow_tree(default_rules(), p);
  const std::size_t arteries = net.vessel_count(), nodes = net.node_count();
  std::vector<unsigned char> leaves(nodes, 1);
  for (std::size_t v = 0; v < arteries; ++v) leaves[static_cast<std::size_t>(net.from[v])] = 0;
  std::size_t terminals = 0;
  for (std::size_t v = 0; v < arteries; ++v) terminals += leaves[static_cast<std::size_t>(net.to[v])];

  VenousMirror mirror;
  mirror.mean_flow = 1e-10;
  mirror.venous_pressure = 1333.22;
  add_venous_mirror(net, mirror);
  ASSERT_EQ(net.vessel_count(), 2 * arteries);
  EXPECT_EQ(net.node_count(), 2 * nodes - terminals);  // capillary ends shared
  for (std::size_t v = 0; v < net.vessel_count(); ++v) EXPECT_GE(net.generation[v], 0);

  // It passes through the format (version 2) unchanged in shape.
  const std::filesystem::path file = std::filesystem::temp_directory_path() /
                                     ("hemotree-venous-" + std::to_string(::getpid()) + ".json");
  {
    OutputStream out(file.string());
    write_network(net, out);
    out.commit();
  }
  const Network back = read_network(file.string());
  std::filesystem::remove(file);
  ASSERT_EQ(back.boundaries.size(), 2u);
  EXPECT_EQ(back.vessel_count(), net.vessel_count());

  Blood blood;
  blood.rheology = Rheology::newtonian;  // one viscosity: twins of one size resist alike
  const SteadyFlow s = solve_steady_flow(net, vessel_resistances(net, blood), 0.0);
  double inflow_pressure = 0;
  for (const NodeBoundary& b : net.boundaries)
    if (b.type == BoundaryType::flow) inflow_pressure = s.node_pressure[static_cast<std::size_t>(b.node)];
  const double midway = 0.5 * (inflow_pressure + mirror.venous_pressure);
  for (std::size_t k = 0; k < arteries; ++k) {
    const std::size_t twin = 2 * arteries - 1 - k;  // appended in reverse order
    EXPECT_NEAR(s.flow[twin], s.flow[k], 1e-9 * mirror.mean_flow) << "vessel " << net.id[k];
    const auto end = static_cast<std::size_t>(net.to[k]);
    if (leaves[end]) {
      EXPECT_NEAR(s.node_pressure[end], midway, 1e-9 * inflow_pressure) << "node " << net.node_id[end];
    }
  }
}
