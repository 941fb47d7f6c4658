// The identity a checkpoint carries (solver/run_identity.hpp): changing any one member of the
// network, or any one option that shapes the state, changes it; what does not shape the
// state (the run's length, its outputs, the threads, who made the file) does not.
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "network_builders.hpp"
#include "solver/run_identity.hpp"

namespace hemotree {
namespace {

using namespace test_networks;

Network two_vessels() {
  const double d = 3e-3, a = std::numbers::pi / 4 * d * d;
  Network net = chain(2, 0.2, d, beta_for_wave_speed(5.0, a), 1e4, newtonian(4e-3));
  net.x = {0, 0.1, 0.2};
  net.y = {0, 0, 0};
  net.z = {0, 0, 0};
  net.distal_diameter = {std::numeric_limits<double>::quiet_NaN(), 0.9 * d};
  net.inlet = Inlet{0, tabulate([](double t) { return 5e-6 + 1e-6 * t; }, 0.1, 11, 0.1)};
  net.outlets.push_back(resistance_outlet(1, 2e9, 0));
  return net;
}

// The smallest change of a number: one step of its last bit.
void nudge(double& x) { x = std::nextafter(x, INFINITY); }

TEST(RunIdentity, EveryMemberOfTheNetworkIsInIt) {
  const Network base = two_vessels();
  const std::uint64_t identity = network_identity(base);
  EXPECT_EQ(network_identity(two_vessels()), identity);
  const std::vector<std::pair<const char*, std::function<void(Network&)>>> changes = {
      {"node_id", [](Network& n) { n.node_id[2] = 7; }},
      {"x", [](Network& n) { nudge(n.x[1]); }},
      {"y", [](Network& n) { nudge(n.y[1]); }},
      {"z", [](Network& n) { nudge(n.z[1]); }},
      {"id", [](Network& n) { n.id[1] = 9; }},
      {"from", [](Network& n) { n.from[1] = 0; }},
      {"to", [](Network& n) { n.to[0] = 2; }},
      {"length", [](Network& n) { nudge(n.length[1]); }},
      {"diameter", [](Network& n) { nudge(n.diameter[1]); }},
      {"wall_thickness", [](Network& n) { nudge(n.wall_thickness[1]); }},
      {"youngs_modulus", [](Network& n) { nudge(n.youngs_modulus[1]); }},
      {"generation", [](Network& n) { n.generation[1] = 5; }},
      {"vessel_class", [](Network& n) { n.vessel_class[1] = VesselClass::capillary; }},
      {"beta", [](Network& n) { nudge(n.beta[1]); }},
      {"reference_pressure", [](Network& n) { nudge(n.reference_pressure[1]); }},
      {"distal_diameter", [](Network& n) { nudge(n.distal_diameter[1]); }},
      {"distal_diameter (none)", [](Network& n) { n.distal_diameter.clear(); }},
      {"blood", [](Network& n) { nudge(n.blood->hematocrit); }},
      {"blood (none)", [](Network& n) { n.blood.reset(); }},
      {"inlet", [](Network& n) { nudge(n.inlet->waveform.value[3]); }},
      {"outlets", [](Network& n) { nudge(n.outlets[0].r); }},
      {"outlet's vessel", [](Network& n) { n.outlets[0].vessel = 0; }},
      {"boundaries", [](Network& n) { n.boundaries.push_back(as_node_boundary(n, n.outlets[0])); }},
  };
  for (const auto& [member, change] : changes) {
    Network changed = two_vessels();
    change(changed);
    EXPECT_NE(network_identity(changed), identity) << member;
  }
  // Who made the file, and members this version does not read, shape nothing.
  Network relabelled = two_vessels();
  relabelled.provenance["tool"] = "another";
  relabelled.extra["notes"] = "measured";
  EXPECT_EQ(network_identity(relabelled), identity);
}

RunConfiguration with_tracer_and_probe(const Network& net) {
  RunConfiguration c;
  c.probes.push_back({0, net.id[0], 0.5});
  TracerSpec t;
  t.name = "dye";
  c.tracers.push_back(t);
  return c;
}

TEST(RunIdentity, EveryOptionThatShapesTheStateIsInIt) {
  const Network net = two_vessels();
  const RunConfiguration base = with_tracer_and_probe(net);
  const double dt = 1e-4;
  const std::string shaping = state_shaping(base, net, dt, Rheology::newtonian);
  const std::vector<std::pair<const char*, std::function<void(RunConfiguration&)>>> changes = {
      {"model", [](RunConfiguration& c) { c.solver.model = ModelChoice::automatic; }},
      {"lumped_transit", [](RunConfiguration& c) { nudge(c.solver.lumped_transit); }},
      {"lumped_rc", [](RunConfiguration& c) { nudge(c.solver.lumped_rc); }},
      {"lumped_sections", [](RunConfiguration& c) { c.solver.lumped_sections = 2; }},
      {"lumped_step", [](RunConfiguration& c) { nudge(c.solver.lumped_step); }},
      {"lumped_passes", [](RunConfiguration& c) { c.solver.lumped_passes = 2; }},
      {"coupling_passes", [](RunConfiguration& c) { c.solver.coupling_passes = 2; }},
      {"degree", [](RunConfiguration& c) { c.solver.degree = 3; }},
      {"low degree", [](RunConfiguration& c) { c.solver.degree_rule.low = 0; }},
      {"high degree", [](RunConfiguration& c) { c.solver.degree_rule.high = 6; }},
      {"raise degree", [](RunConfiguration& c) { c.solver.degree_rule.raise_to = 3; }},
      {"short vessel", [](RunConfiguration& c) { nudge(c.solver.degree_rule.short_vessel); }},
      {"harmonics", [](RunConfiguration& c) { c.solver.degree_rule.harmonics = 24; }},
      {"linear error", [](RunConfiguration& c) { nudge(c.solver.degree_rule.linear_error); }},
      {"elements", [](RunConfiguration& c) { c.solver.elements = 2; }},
      {"quadrature", [](RunConfiguration& c) { c.solver.quadrature_points = 9; }},
      {"scheme", [](RunConfiguration& c) { c.solver.scheme = TimeScheme::runge_kutta4; }},
      {"cfl", [](RunConfiguration& c) { nudge(c.solver.cfl); }},
      {"friction safety", [](RunConfiguration& c) { nudge(c.solver.friction_safety); }},
      {"external pressure", [](RunConfiguration& c) { nudge(c.solver.external_pressure); }},
      {"thick wall ratio", [](RunConfiguration& c) { nudge(c.solver.thick_wall_ratio); }},
      {"start", [](RunConfiguration& c) { c.solver.start = StartChoice::rest; }},
      {"steady start", [](RunConfiguration& c) { c.solver.start = StartChoice::steady; }},
      {"balance", [](RunConfiguration& c) { c.balance_compliances = false; }},
      {"sample interval", [](RunConfiguration& c) { nudge(c.sample_interval); }},
      {"probe position", [](RunConfiguration& c) { nudge(c.probes[0].x); }},
      {"probes", [](RunConfiguration& c) { c.probes.clear(); }},
      {"red cells", [](RunConfiguration& c) { c.red_cells = RedCells::transport; }},
      {"tracer name", [](RunConfiguration& c) { c.tracers[0].name = "ink"; }},
      {"tracer carrier", [](RunConfiguration& c) { c.tracers[0].carrier = TracerCarrier::cells; }},
      {"tracer place", [](RunConfiguration& c) {
         c.tracers[0].place = TracerSpec::Place::vessel;
         c.tracers[0].at = 1;
       }},
      {"tracer shape", [](RunConfiguration& c) { c.tracers[0].shape = TracerSpec::Shape::step; }},
      {"tracer start", [](RunConfiguration& c) { nudge(c.tracers[0].start); }},
      {"tracer duration", [](RunConfiguration& c) { nudge(c.tracers[0].duration); }},
      {"tracer concentration", [](RunConfiguration& c) { nudge(c.tracers[0].concentration); }},
      {"tracers", [](RunConfiguration& c) { c.tracers.clear(); }},
      {"transport step", [](RunConfiguration& c) { nudge(c.transport_step); }},
  };
  for (const auto& [option, change] : changes) {
    RunConfiguration changed = base;
    change(changed);
    EXPECT_NE(state_shaping(changed, net, dt, Rheology::newtonian), shaping) << option;
  }
  // A periodic start is shaped by the harmonics it takes; another start is not.
  RunConfiguration periodic = base, more_harmonics = base;
  periodic.solver.start = more_harmonics.solver.start = StartChoice::periodic;
  more_harmonics.solver.periodic_harmonics = 12;
  EXPECT_NE(state_shaping(more_harmonics, net, dt, Rheology::newtonian), state_shaping(periodic, net, dt, Rheology::newtonian));
  RunConfiguration steady = base, steady_more = base;
  steady.solver.start = steady_more.solver.start = StartChoice::steady;
  steady_more.solver.periodic_harmonics = 12;
  EXPECT_EQ(state_shaping(steady_more, net, dt, Rheology::newtonian), state_shaping(steady, net, dt, Rheology::newtonian));
  // The step and the rheology the run takes.
  double later = dt;
  nudge(later);
  EXPECT_NE(state_shaping(base, net, later, Rheology::newtonian), shaping);
  EXPECT_NE(state_shaping(base, net, dt, Rheology::pries), shaping);
  // What does not shape the state: how long it runs, how often it is saved, what it writes
  // besides, the threads, the step asked for (the step taken is dt), the names.
  RunConfiguration same = base;
  same.network_name = "another name";
  same.out_dir = "elsewhere";
  same.cycles = 7;
  same.until_periodic = true;
  same.periodic_tolerance = 1e-3;
  same.max_cycles = 9;
  same.checkpoint_every = 2;
  same.resume = true;
  same.frames = 4;
  same.vtk = true;
  same.vtk_keep = {1, 0};
  same.force = true;
  same.solver.threads = 2;
  same.solver.dt = 5e-5;
  same.solver.rheology_override = static_cast<int>(Rheology::newtonian);
  EXPECT_EQ(state_shaping(same, net, dt, Rheology::newtonian), shaping);
}

TEST(RunIdentity, ItsValueFollowsBothParts) {
  const Network net = two_vessels();
  const RunConfiguration c = with_tracer_and_probe(net);
  const RunIdentity a = run_identity(net, c, 1e-4, Rheology::newtonian);
  EXPECT_EQ(run_identity(net, c, 1e-4, Rheology::newtonian).value(), a.value());
  Network other = two_vessels();
  nudge(other.length[0]);
  EXPECT_NE(run_identity(other, c, 1e-4, Rheology::newtonian).value(), a.value());
  EXPECT_NE(run_identity(net, c, 2e-4, Rheology::newtonian).value(), a.value());
}

}  // namespace
}  // namespace hemotree
