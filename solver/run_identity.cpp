#include "solver/run_identity.hpp"

#include <limits>
#include <sstream>

#include "formats/checkpoint_file.hpp"

namespace hemotree {

namespace {

// Each array prefixed by its name and length, so that no two different networks serialise
// to the same bytes by moving values from one array to the next.
class CanonicalHash {
 public:
  template <class T>
  void array(std::string_view name, const std::vector<T>& values) {
    f_.add(name);
    const std::uint64_t n = values.size();
    f_.add(&n, sizeof n);
    f_.add(values);
  }
  void text(std::string_view name, std::string_view value) {
    f_.add(name);
    const std::uint64_t n = value.size();
    f_.add(&n, sizeof n);
    f_.add(value);
  }
  std::uint64_t value() const { return f_.value(); }

 private:
  Fingerprint f_;
};

}  // namespace

std::uint64_t network_identity(const Network& net) {
  // Every member, by name: a member added to Network stops this from compiling.
  const auto& [node_id, x, y, z, id, from, to, length, diameter, wall_thickness, youngs_modulus, generation,
               vessel_class, beta, reference_pressure, distal_diameter, blood, inlet, outlets, boundaries,
               provenance, extra] = net;
  // Not the state's: who made the file (provenance) and the top-level members this version
  // does not read (extra), which no solver sees.
  (void)provenance, (void)extra;
  CanonicalHash h;
  h.array("node_id", node_id);
  h.array("x", x);
  h.array("y", y);
  h.array("z", z);
  h.array("id", id);
  h.array("from", from);
  h.array("to", to);
  h.array("length", length);
  h.array("diameter", diameter);
  h.array("wall_thickness", wall_thickness);
  h.array("youngs_modulus", youngs_modulus);
  h.array("generation", generation);
  h.array("vessel_class", vessel_class);
  h.array("beta", beta);
  h.array("reference_pressure", reference_pressure);
  h.array("distal_diameter", distal_diameter);
  // The conditions in their file form (docs/network-format.md): the writer's own fields,
  // numbers at full precision.
  h.text("blood", blood ? to_json(*blood).dump() : "none");
  h.text("inlet", inlet ? to_json(*inlet).dump() : "none");
  for (const Outlet& o : outlets) h.text("outlet", to_json(o).dump() + " at vessel " + std::to_string(o.vessel));
  for (const NodeBoundary& b : boundaries)
    h.text("boundary", to_json(b, node_id[static_cast<std::size_t>(b.node)]).dump());
  return h.value();
}

std::string state_shaping(const RunConfiguration& config, const Network& net, double dt, Rheology rheology) {
  const auto& [network_name, network_in_slices, out_dir, solver, cycles, until_periodic, periodic_tolerance, max_cycles, settling_step,
               settling_degree, balance_compliances, checkpoint_every, resume, sample_interval, probes, red_cells,
               tracers, transport_step, frames, vtk, vtk_keep, results_format, force, words] = config;
  // Not the state's: names and folders, how long the run goes on (a resume may extend it),
  // how often it is saved, what it writes besides, and what it may be forced through.
  // The settling cycle is taken before the run's first (a resume continues after it).
  (void)network_name, (void)network_in_slices, (void)out_dir, (void)cycles, (void)until_periodic, (void)periodic_tolerance,
      (void)max_cycles, (void)settling_step, (void)settling_degree, (void)checkpoint_every, (void)resume, (void)frames, (void)vtk, (void)vtk_keep, (void)results_format, (void)force, (void)words;
  const auto& [model, lumped_transit, lumped_rc, lumped_sections, lumped_step, coupling_passes, lumped_passes, degree, degree_rule, elements,
               quadrature_points, scheme, asked_dt, cfl, friction_safety, external_pressure, thick_wall_ratio,
               start, periodic_harmonics, rheology_override, threads] = solver;
  // The step taken is dt (asked_dt only proposes it); the rheology taken is `rheology`
  // (the override only chooses it); threads change the sums' order, which the solver keeps
  // within round-off (docs/solver.md), and a resume may use the idle cores.
  (void)asked_dt, (void)rheology_override, (void)threads;
  const auto& [low, high, raise_to, short_vessel, harmonics, linear_error] = degree_rule;

  std::ostringstream s;
  s.precision(std::numeric_limits<double>::max_digits10);  // every bit: 6 digits let 0.10000001 pass as 0.1
  s << "model " << to_string(model) << " (" << lumped_transit << ", " << lumped_rc << ", " << lumped_step << ", "
    << lumped_passes << " passes, " << coupling_passes << " coupling passes, " << lumped_sections << " sections), scheme " << to_string(scheme) << ", degree "
    << (degree == SolverOptions::automatic ? std::string("auto") : std::to_string(degree)) << " (" << low << "/"
    << raise_to << "/" << high << ", linear error " << linear_error << ", short " << short_vessel << " of harmonic "
    << harmonics << "), elements " << elements << ", quadrature " << quadrature_points << ", time step " << dt
    << " (cfl " << cfl << ", friction safety " << friction_safety << "), rheology " << to_string(rheology)
    << ", start " << to_string(start)
    << (start == StartChoice::periodic ? " of " + std::to_string(periodic_harmonics) + " harmonics" : std::string()) << ", external pressure " << external_pressure
    << " Pa, thick wall ratio " << thick_wall_ratio << ", balance " << (balance_compliances ? "on" : "off")
    << ", sample interval " << sample_interval << " s, probes";
  for (const Probe& p : probes) {
    const auto& [vessel, probe_id, at] = p;
    (void)vessel;  // the index of probe_id
    s << ' ' << probe_id << ':' << at;
  }
  s << ", red cells " << to_string(red_cells);
  for (const TracerSpec& t : tracers) {
    const auto& [name, carrier, place, index, shape, start, duration, concentration] = t;
    const char* where = place == TracerSpec::Place::inlet ? "inlet" : place == TracerSpec::Place::node ? "node:" : "vessel:";
    s << ", tracer " << name << " (" << to_string(carrier) << ", at " << where;
    if (place == TracerSpec::Place::node) s << net.node_id[static_cast<std::size_t>(index)];
    if (place == TracerSpec::Place::vessel) s << net.id[static_cast<std::size_t>(index)];
    s << ", " << (shape == TracerSpec::Shape::bolus ? "bolus" : "step") << " from " << start << " s for " << duration
      << " s, concentration " << concentration << ")";
  }
  if (config.carries_transport()) s << ", transport every " << transport_step << " of the period";
  return s.str();
}

std::uint64_t RunIdentity::value() const {
  CanonicalHash h;
  h.text("network", std::string_view(reinterpret_cast<const char*>(&network), sizeof network));
  h.text("shaping", shaping);
  return h.value();
}

RunIdentity run_identity(const Network& net, const RunConfiguration& config, double dt, Rheology rheology) {
  return {network_identity(net), state_shaping(config, net, dt, rheology)};
}

}  // namespace hemotree
