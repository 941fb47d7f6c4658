// openBF's YAML models read into a Network (the file, a vessel's keys and the inlet table are
// read in openbf_yaml.cpp, openbf_vessel.cpp, openbf_inlet.cpp). What each key means is
// openBF's own reading of it (src/vessel.jl, network.jl, solver.jl, boundary_conditions.jl of
// openBF 2.x), or, where that code departs from openBF's documentation (docs/src/man/config.md)
// and on request, the documentation's; docs/import.md has the table and the differences.
#include <algorithm>
#include <deque>
#include <filesystem>

#include "core/setting_error.hpp"
#include "exchange/openbf_model.hpp"

namespace hemotree {

namespace openbf {

namespace {

namespace fs = std::filesystem;

fs::path beside(const std::string& yaml_path, const std::string& name) {
  const fs::path p(name);
  return p.is_absolute() ? p : fs::path(yaml_path).parent_path() / p;
}

std::string plural(std::size_t n, std::string_view what) {
  return std::to_string(n) + " " + std::string(what) + (n == 1 ? "" : "s");
}

// --- the network ---------------------------------------------------------------------------

struct Topology {
  std::map<std::int64_t, std::vector<std::size_t>> leaving, entering;  // node id -> vessel positions
};

Topology topology_of(const std::vector<VesselModel>& vessels) {
  Topology t;
  for (std::size_t k = 0; k < vessels.size(); ++k) {
    t.leaving[vessels[k].sn].push_back(k);
    t.entering[vessels[k].tn].push_back(k);
  }
  return t;
}

// Generations: the number of vessels between the inlet node and a vessel's nearer end.
// openBF networks need not be trees (the circle of Willis closes a loop), so this is a
// breadth-first search over the undirected graph; a vessel it cannot reach is refused.
std::vector<std::int32_t> generations(const Source& source, const std::vector<VesselModel>& vessels,
                                      std::int64_t inlet_node) {
  std::map<std::int64_t, std::vector<std::size_t>> touching;
  for (std::size_t k = 0; k < vessels.size(); ++k) {
    touching[vessels[k].sn].push_back(k);
    touching[vessels[k].tn].push_back(k);
  }
  std::map<std::int64_t, std::int32_t> depth{{inlet_node, 0}};
  std::deque<std::int64_t> queue{inlet_node};
  while (!queue.empty()) {
    const std::int64_t n = queue.front();
    queue.pop_front();
    for (std::size_t k : touching[n]) {
      const std::int64_t other = vessels[k].sn == n ? vessels[k].tn : vessels[k].sn;
      if (depth.emplace(other, depth[n] + 1).second) queue.push_back(other);
    }
  }
  std::vector<std::int32_t> g(vessels.size());
  for (std::size_t k = 0; k < vessels.size(); ++k) {
    const auto a = depth.find(vessels[k].sn), b = depth.find(vessels[k].tn);
    if (a == depth.end())
      source.fail(vessels[k].mark, "vessel " + std::to_string(k + 1) + " (" + vessels[k].label +
                                       ") is not connected to the inlet node " + std::to_string(inlet_node));
    g[k] = std::min(a->second, b->second);
  }
  return g;
}

// One velocity profile and one external pressure for the whole network: hemotree has one
// blood.alpha and one interstitial pressure. openBF 2.x's code reads "gamma_profile" only:
// where a file spells it "gamma profile" (openBF 1.x), the code takes its default.
struct NetworkWide {
  double profile, external_pressure;
  std::size_t spaced_profiles;  // vessels giving it as "gamma profile"
};

NetworkWide one_profile_and_external_pressure(const Source& source, const std::vector<VesselModel>& vessels,
                                              bool as_coded) {
  std::size_t spaced_profiles = 0;
  const auto profile_of = [&](const VesselModel& v) {
    return as_coded && v.profile_spaced ? default_profile : v.profile.value_or(default_profile);
  };
  for (const VesselModel& v : vessels) spaced_profiles += v.profile_spaced;
  const double profile = profile_of(vessels.front());
  const double external_pressure = vessels.front().external_pressure;
  for (std::size_t k = 1; k < vessels.size(); ++k) {
    const VesselModel& v = vessels[k];
    if (profile_of(v) != profile)
      source.fail(v.profile.has_value() ? v.profile_mark : v.mark,
                  "vessel " + std::to_string(k + 1) + ": gamma_profile " + format_number(profile_of(v)) +
                      " differs from vessel 1's " + format_number(profile) +
                      ": hemotree has one velocity profile (blood alpha) for the network");
    if (v.external_pressure != external_pressure)
      source.fail(v.external_pressure_mark.line >= 0 ? v.external_pressure_mark : v.mark,
                  "vessel " + std::to_string(k + 1) + ": Pext " + format_number(v.external_pressure) +
                      " Pa differs from vessel 1's " + format_number(external_pressure) +
                      " Pa: hemotree takes one external pressure for the network");
  }
  return {profile, external_pressure, spaced_profiles};
}

// The inlet: openBF 2.x feeds node 1 from inlet_file (default PROJECT_inlet.dat); 1.x marked
// the vessel with "inlet: Q" and named its file there.
struct InletChoice {
  std::size_t vessel;           // its position in the model
  std::string file, named_by;  // the inlet table, and where the model names it
};

InletChoice find_inlet(const Source& source, const Fields& top, const std::vector<VesselModel>& vessels,
                       const Topology& topo, const std::string& project_name, std::string inlet_file,
                       const YAML::Mark& inlet_file_mark) {
  const std::string& path = source.path;
  std::size_t inlet_vessel = vessels.size();
  std::string inlet_named_by;
  for (std::size_t k = 0; k < vessels.size(); ++k) {
    if (!vessels[k].inlet) continue;
    if (inlet_vessel != vessels.size())
      source.fail(vessels[k].inlet_mark, "vessel " + std::to_string(k + 1) +
                                             ": a second inlet; hemotree's openBF import takes one");
    if (!inlet_file.empty())
      source.fail(vessels[k].inlet_mark, "vessel " + std::to_string(k + 1) + ": \"inlet\" with a top-level inlet_file");
    inlet_vessel = k;
    inlet_file = vessels[k].inlet_file;
    inlet_named_by = "named on " + path + ":" + std::to_string(vessels[k].inlet_mark.line + 1);
  }
  if (inlet_vessel == vessels.size()) {
    const auto at_one = topo.leaving.find(1);
    if (at_one == topo.leaving.end())
      source.fail(top.mark(), "no vessel has \"sn\": 1, the node openBF feeds from the inlet file");
    if (at_one->second.size() > 1)
      source.fail(vessels[at_one->second[1]].mark,
                  "vessels " + std::to_string(at_one->second[0] + 1) + " and " + std::to_string(at_one->second[1] + 1) +
                      " both leave the inlet node 1; openBF's inlet feeds one vessel");
    inlet_vessel = at_one->second.front();
    if (inlet_file.empty()) {
      if (project_name.empty())
        source.fail(top.mark(), "no inlet_file and no project_name to name PROJECT_inlet.dat");
      inlet_file = project_name + "_inlet.dat";
      inlet_named_by = "openBF's default for project_name " + project_name;
    } else {
      inlet_named_by = "named on " + path + ":" + std::to_string(inlet_file_mark.line + 1);
    }
  }
  return {inlet_vessel, inlet_file, inlet_named_by};
}

// No vessel ends at the inlet node; every other node is entered by a vessel (openBF has no other
// source of flow), and an outlet node by exactly one (its 0D model sits at that vessel's end).
void check_nodes(const Source& source, const std::vector<VesselModel>& vessels, const Topology& topo,
                 std::int64_t inlet_node) {
  if (topo.entering.contains(inlet_node))
    source.fail(vessels[topo.entering.at(inlet_node).front()].mark,
                "vessel " + std::to_string(topo.entering.at(inlet_node).front() + 1) + ": ends at the inlet node " +
                    std::to_string(inlet_node));
  for (const auto& [node, from_here] : topo.leaving)
    if (node != inlet_node && !topo.entering.contains(node))
      source.fail(vessels[from_here.front()].mark,
                  "node " + std::to_string(node) + ": vessels leave it but none enters it, and it is not the inlet");
  for (const auto& [node, into] : topo.entering)
    if (!topo.leaving.contains(node) && into.size() > 1)
      source.fail(vessels[into[1]].mark, "node " + std::to_string(node) + ": vessels " + std::to_string(into[0] + 1) +
                                             " and " + std::to_string(into[1] + 1) +
                                             " end there and none leaves it; openBF has no outlet shared by two vessels");
}

// openBF's blood: Newtonian, with the momentum-flux coefficient of its velocity profile.
Blood openbf_blood(double density, double viscosity, double profile, bool as_coded) {
  Blood blood;
  blood.density = density;
  blood.rheology = Rheology::newtonian;
  blood.newtonian_viscosity = viscosity;
  blood.alpha = alpha_of_profile(profile);
  // openBF's code writes its momentum flux with alpha = 1 whatever the profile, which sets
  // its friction only (docs/import.md).
  if (as_coded) blood.momentum_flux_coefficient = 1;
  return blood;
}

// What the reading assumed or chose, counted for its notes.
struct Tally {
  std::size_t law_walls = 0, tapered_law_walls = 0, ratio_walls = 0, open_ends = 0, wk2 = 0, wk3_without_r2 = 0;
  std::size_t tapers = 0, spaced_profiles = 0;
};

// The outlet: at a vessel whose end no vessel leaves. openBF decides by the keys given
// (vessel.jl), "outlet" only names the kind: R1, R2 and Cc a three-element Windkessel;
// R1 and Cc alone a two-element one; Rt (or nothing) a reflection coefficient (0 by
// default: non-reflecting). The two-element Windkessel's R1 is, in openBF's documentation,
// the total resistance, split into the vessel's characteristic impedance Z and R1 - Z; its
// code keeps R1 before the compliance and puts R2 = R1 - Z beyond it (total 2 R1 - Z).
Outlet openbf_outlet(const Source& source, const VesselModel& v, std::size_t k, const std::string& name,
                     double density, double rd, bool as_coded, Tally& tally) {
  // Messages point at the key at fault, or at the vessel for one missing.
  const auto fail = [&](std::string_view key, const std::string& what) {
    const auto e = v.outlet_keys.find(key);
    source.fail(e != v.outlet_keys.end() ? e->second->mark : v.mark, name + ": " + what);
  };
  Outlet o;
  o.vessel = static_cast<std::int32_t>(k);
  const bool windkessel = !std::isnan(v.r1) || !std::isnan(v.r2) || !std::isnan(v.cc);
  if (windkessel) {
    if (!std::isnan(v.rt)) fail("Rt", "give a Windkessel (R1, R2, Cc) or a reflection coefficient (Rt), not both");
    if (v.outlet_kind == "reflection") fail("outlet", "\"outlet\": reflection with Windkessel keys (R1, R2, Cc)");
    if (std::isnan(v.r1)) fail("", "a Windkessel outlet needs \"R1\"");
    if (std::isnan(v.cc)) fail("", "a Windkessel outlet needs \"Cc\"");
    o.type = BoundaryType::rcr;
    o.c = v.cc;
    o.p_out = std::isnan(v.pout) ? 0.0 : v.pout;
    if (!std::isnan(v.r2) && v.r2 != 0) {
      if (v.outlet_kind == "wk2") fail("outlet", "\"outlet\": wk2 with \"R2\" (a two-element Windkessel has one resistance)");
      if (v.r1 == 0) fail("R1", "\"R1\" = 0: openBF reads a zero proximal resistance as a reflection outlet");
      o.r1 = v.r1;
      o.r2 = v.r2;
    } else {
      // Z at the vessel's last cell: at Rd as documented, at (about) Rp in the code.
      const double z = characteristic_impedance(density, v.youngs_modulus,
                                                std::isnan(v.wall) ? avolio_wall_thickness(rd) : v.wall, rd);
      if (!(v.r1 > z))
        fail("R1", "\"R1\" " + format_number(v.r1) + " Pa s/m^3 of a two-element Windkessel is not above the vessel's "
             "characteristic impedance Z = " + format_number(z) + " Pa s/m^3, so R2 = R1 - Z would not be positive");
      o.r1 = as_coded ? v.r1 : z;
      o.r2 = v.r1 - z;
      ++tally.wk2;
      if (v.outlet_kind == "wk3") ++tally.wk3_without_r2;
    }
  } else {
    if (!std::isnan(v.pout)) fail("Pout", "\"Pout\" belongs to a Windkessel outlet (R1, R2, Cc)");
    if (v.outlet_kind == "wk2" || v.outlet_kind == "wk3") fail("outlet", "\"outlet\": " + v.outlet_kind + " without R1 and Cc");
    o.type = BoundaryType::reflection;
    o.reflection = std::isnan(v.rt) ? 0.0 : v.rt;
    if (!has_outlet(v)) ++tally.open_ends;
  }
  return o;
}

// What was assumed, one line each.
// Where openBF's code and its documentation part, one line each: what was built, and how to
// get the other reading (docs/import.md).
void note_readings(const ImportOptions& options, bool as_coded, const Tally& tally,
                   const std::vector<VesselModel>& vessels, const Blood& blood, double external_pressure,
                   const std::set<std::string, std::less<>>& ignored) {
  const std::size_t tapers = tally.tapers, spaced_profiles = tally.spaced_profiles, wk2 = tally.wk2,
                    wk3_without_r2 = tally.wk3_without_r2, law_walls = tally.law_walls,
                    tapered_law_walls = tally.tapered_law_walls, ratio_walls = tally.ratio_walls,
                    open_ends = tally.open_ends;
  const std::string reading_note = as_coded ? " (openBF's code; " + placeholder("as_documented") + " for its documentation's reading)"
                                            : " (openBF's documentation; its code differs: vimport's default)";
  if (tapers > 0)
    options.note(plural(tapers, "tapered vessel") + " (Rp != Rd): " +
                 (as_coded ? "uniform at Rp, as openBF's code builds them (its radius changes by (Rd - Rp) dx, dx <= 1 mm, "
                             "along the vessel), where its documentation tapers them linearly to Rd"
                           : "tapered linearly from Rp to Rd, as openBF documents them; its code keeps them uniform at Rp") +
                 reading_note);
  if (spaced_profiles > 0)
    options.note("\"gamma profile\" (openBF 1.x's spelling) on " + plural(spaced_profiles, "vessel") + ": " +
                 (as_coded ? "not read by openBF 2.x's code, which takes its default gamma_profile 2 (friction 8 pi mu, "
                             "blood alpha 4/3), where the documented key gives gamma " +
                                 format_number(vessels.front().profile.value_or(default_profile))
                           : "read as the profile exponent gamma (blood alpha " + three_digits(blood.alpha) +
                                 "), which openBF 2.x's code ignores for its default 2") +
                 reading_note);
  if (wk2 > 0)
    options.note(plural(wk2, "two-element Windkessel outlet") + " (R1 and Cc" +
                 (wk3_without_r2 > 0 ? ", " + std::to_string(wk3_without_r2) + " of them marked wk3 without R2" : "") +
                 "): " +
                 (as_coded ? "R1 kept before the compliance and R2 = R1 - Z beyond it, Z the vessel's characteristic "
                             "impedance (total 2 R1 - Z), as openBF's code builds them; its documentation makes R1 the "
                             "total, split into Z and R1 - Z"
                           : "R1 taken as the total resistance, split into the vessel's characteristic impedance Z and "
                             "R1 - Z, as openBF documents it; its code adds R2 = R1 - Z to R1") +
                 reading_note);
  if (law_walls > 0)
    options.note("wall thickness from openBF's law h0 = R (0.2802 e^(-505.3 R) + 0.1324 e^(-11.14 R)) [R in m] for " +
                 plural(law_walls, "vessel") +
                 (tapered_law_walls > 0 ? " (at the mean radius for the " + plural(tapered_law_walls, "tapered vessel") + ")"
                  : as_coded && tapers > 0 ? " (at Rp, as openBF's code has it, for the tapered ones)"
                                           : std::string()));
  if (ratio_walls > 0)
    options.note("wall thickness h = " + format_number(*options.wall_ratio) + " D for " + plural(ratio_walls, "vessel") +
                 " without h0 (" + placeholder("wall_ratio") + ")");
  if (open_ends > 0)
    options.note(plural(open_ends, "outlet") + " without outlet keys: openBF's default, non-reflecting (Rt = 0)");
  options.note("tube laws: openBF's thin wall, each vessel's beta = 4 E h0 / (3 sqrt(pi) R^2) at its reference_pressure, "
               "openBF's external pressure Pext = " + format_number(external_pressure) +
               " Pa; hemosolve's " + placeholder("thick_wall_ratio") + " and " + placeholder("external_pressure") +
               " do not change them");
  options.note(as_coded ? "momentum flux: alpha = 1 (blood momentum_flux_coefficient), as openBF's code has it; the "
                         "friction and the wall shear stress from the profile (blood alpha " + three_digits(blood.alpha) + ")" +
                             reading_note
                       : "momentum flux: blood alpha " + three_digits(blood.alpha) +
                             " in the flux as in the friction, as openBF documents the profile; its code takes 1 in "
                             "the flux" + reading_note);
  if (!ignored.empty()) {
    std::string list;
    for (const std::string& k : ignored) list += (list.empty() ? "" : ", ") + k;
    options.note("openBF solver and output settings ignored: " + list);
  }
}
}  // namespace

}  // namespace openbf

Network read_openbf(const std::string& path, const ImportOptions& options, OpenbfReading reading) {
  using namespace openbf;
  const bool as_coded = reading == OpenbfReading::code;
  const Source source{path};
  const YAML::Node root = load_yaml(path);
  if (!root.IsMap()) source.fail(root.Mark(), "an openBF model is a mapping with \"network\", \"blood\" and \"solver\"");
  const Fields top(source, root, "model", [](const std::string& key) -> std::string {
    static const std::set<std::string, std::less<>> known = {
        "project_name", "project name", "inlet_file", "write_results", "output_directory", "solver", "blood", "network"};
    return known.contains(key) ? "" : "\"" + key + "\" is not an openBF key that hemotree reads or may safely ignore";
  });

  std::set<std::string, std::less<>> ignored;
  std::string project_name, inlet_file;
  YAML::Mark inlet_file_mark;
  double density = unset, viscosity = unset;
  std::vector<VesselModel> vessels;
  std::deque<Fields> vessel_fields;  // the vessels' entries, which VesselModel points into

  for (const Entry& e : top.entries()) {
    if (e.key == "project_name" || e.key == "project name") {
      project_name = top.text(e);
    } else if (e.key == "inlet_file") {
      inlet_file = top.text(e);
      inlet_file_mark = e.mark;
    } else if (e.key == "write_results" || e.key == "output_directory") {
      ignored.insert(e.key);
    } else if (e.key == "solver") {
      const Fields solver(source, e.value, "solver", [](const std::string& key) -> std::string {
        static const std::set<std::string, std::less<>> known = {"Ccfl", "cycles", "jump", "convergence_tolerance",
                                                                 "convergence tolerance"};
        return known.contains(key) ? "" : "\"" + key + "\" is not an openBF solver setting that hemotree knows";
      });
      for (const Entry& s : solver.entries()) ignored.insert(s.key);
    } else if (e.key == "blood") {
      const Fields blood(source, e.value, "blood", [](const std::string& key) -> std::string {
        return key == "rho" || key == "mu" ? "" : "\"" + key + "\" is not an openBF blood key (rho, mu)";
      });
      density = blood.number(blood.require("rho"), ranges::density);
      viscosity = blood.number(blood.require("mu"), ranges::viscosity);
    } else if (e.key == "network") {
      if (!e.value.IsSequence() || e.value.size() == 0)
        top.fail(e, "\"network\" must be a list of vessels");
      for (std::size_t k = 0; k < e.value.size(); ++k)
        vessels.push_back(read_vessel(source, e.value[k], k + 1, ignored, vessel_fields));
    }
  }
  top.require("network");
  top.require("blood");

  const NetworkWide wide = one_profile_and_external_pressure(source, vessels, as_coded);
  const double profile = wide.profile, external_pressure = wide.external_pressure;

  // The inlet: openBF 2.x feeds node 1 from inlet_file (default PROJECT_inlet.dat); 1.x marked
  // the vessel with "inlet: Q" and named its file there.
  const Topology topo = topology_of(vessels);
  const InletChoice inlet_choice =
      find_inlet(source, top, vessels, topo, project_name, inlet_file, inlet_file_mark);
  const std::size_t inlet_vessel = inlet_choice.vessel;
  const std::int64_t inlet_node = vessels[inlet_vessel].sn;
  check_nodes(source, vessels, topo, inlet_node);
  const std::vector<std::int32_t> generation = generations(source, vessels, inlet_node);

  Network net;
  std::map<std::int64_t, std::int32_t> node_index;
  for (const auto& v : vessels) node_index.emplace(v.sn, 0), node_index.emplace(v.tn, 0);
  net.reserve(vessels.size(), node_index.size());
  for (auto& [id, index] : node_index) index = net.add_node(id);

  const Blood blood = openbf_blood(density, viscosity, profile, as_coded);
  net.blood = blood;

  Tally tally;
  tally.spaced_profiles = wide.spaced_profiles;
  nlohmann::json labels = nlohmann::json::array();
  for (std::size_t k = 0; k < vessels.size(); ++k) {
    const VesselModel& v = vessels[k];
    const std::string name = "vessel " + std::to_string(k + 1);
    // openBF's code (vessel.jl) sets the radius of cell i to Rp + (Rd - Rp) / (M - 1) (i - 1) dx:
    // a slope per cell taken as one per metre, so that along the vessel the radius changes by
    // (Rd - Rp) dx, dx <= 1 mm, a thousandth of Rd - Rp or less. Its tapered vessels are
    // uniform at Rp; its documentation tapers them linearly from Rp to Rd.
    tally.tapers += v.rd != v.rp;
    const double rd = as_coded ? v.rp : v.rd;
    double wall = v.wall;
    if (std::isnan(wall)) {
      // openBF evaluates its law along the vessel: at Rp in its code; one thickness per vessel,
      // as documented, is its value at the mean radius (openBF 1.x's choice).
      if (options.wall_ratio) {
        wall = *options.wall_ratio * 2 * v.rp;
        ++tally.ratio_walls;
      } else {
        wall = avolio_wall_thickness((v.rp + rd) / 2);
        ++tally.law_walls;
        if (v.rp != rd) ++tally.tapered_law_walls;
      }
      if (!ranges::wall_thickness.contains(wall))
        source.fail(v.mark, name + ": the wall thickness openBF derives from the radius, " +
                                out_of_range("h0", ranges::wall_thickness, wall));
    }
    net.add_vessel(static_cast<std::int64_t>(k + 1), node_index.at(v.sn), node_index.at(v.tn), v.length, 2 * v.rp,
                   wall, v.youngs_modulus, generation[k]);
    if (rd != v.rp) {
      net.distal_diameter.resize(k, unset);
      net.distal_diameter.push_back(2 * rd);
    }
    // openBF's tube law is the thin wall's (Poisson ratio 1/2) at its external pressure, given
    // here as beta so that no option of hemosolve (its thick-wall law above h/D = 0.1, its one
    // external pressure) changes it; a tapered vessel's beta follows 1 / D^2 (E h constant).
    const double beta = openbf_beta(v.youngs_modulus, wall, v.rp);
    if (!ranges::beta.contains(beta))
      source.fail(v.mark, name + ": openBF's tube law 4 E h0 / (3 sqrt(pi) R^2) gives " + out_of_range("beta", ranges::beta, beta));
    net.beta.push_back(beta);
    net.reference_pressure.push_back(v.external_pressure);
    labels.push_back(v.label);

    // The outlet: at a vessel whose end no vessel leaves.
    const bool terminal = !topo.leaving.contains(v.tn);
    if (!terminal) {
      if (has_outlet(v))
        source.fail(v.first_outlet_key->mark, name + ": outlet key \"" + v.first_outlet_key->key +
                                                  "\" on a vessel whose end node " + std::to_string(v.tn) +
                                                  " other vessels leave");
      continue;
    }
    net.outlets.push_back(openbf_outlet(source, v, k, name, density, rd, as_coded, tally));
  }
  if (!net.distal_diameter.empty()) net.distal_diameter.resize(vessels.size(), unset);

  Inlet inlet;
  inlet.vessel = static_cast<std::int64_t>(inlet_vessel + 1);
  inlet.waveform = read_inlet_table(beside(path, inlet_choice.file).string(), inlet_choice.named_by, options);
  net.inlet = inlet;

  net.provenance = {{"tool", "vimport"}, {"format", "openbf"}, {"source", path}, {"labels", labels}};
  if (!project_name.empty()) net.provenance["project_name"] = project_name;
  net.provenance["external_pressure"] = external_pressure;

  note_readings(options, as_coded, tally, vessels, blood, external_pressure, ignored);
  fill_missing_walls(net, options);
  return net;
}

}  // namespace hemotree
