// vprune: cuts a full tree to a computational budget and replaces every removed subtree by
// an outlet calibrated from it, so the pruned network runs as it is in hemosolve.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include <CLI/CLI.hpp>

#include "cli/errors.hpp"
#include "cli/tool.hpp"
#include "cli/units.hpp"
#include "formats/exports.hpp"
#include "formats/network_io.hpp"
#include "formats/topology.hpp"
#include "pruner/outlet_calibration.hpp"
#include "pruner/pruning_strategies.hpp"

using namespace hemotree;

namespace {

// A measured inflow: two columns, time [s] and flow [m^3/s], comma or space separated,
// '#' comments; the period is given separately.
Waveform read_inflow_table(const std::string& path, double period) {
  std::ifstream in(path);
  if (!in) throw IoError("cannot open inflow table " + path);
  Waveform w;
  w.shape = Waveform::Shape::table;
  w.period = period;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    for (char& c : line)
      if (c == ',' || c == ';' || c == '\t') c = ' ';
    std::istringstream fields(line);
    double t, q;
    if (!(fields >> t)) continue;  // blank line
    if (!(fields >> q))
      throw InputError(path + ":" + std::to_string(number) + ": expected two numbers (time, flow)");
    w.time.push_back(t);
    w.flow.push_back(q);
  }
  return w;
}

std::string mmhg(double pascal) {
  char text[32];
  std::snprintf(text, sizeof text, "%.2f mmHg", pascal / pascal_per_mmhg);
  return text;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Cut a full vascular tree to a computational budget and replace each removed "
               "subtree by a calibrated RCR or R outlet.",
               "vprune"};
  std::string input = "-", output = "-", format_name = "json", strategy = "profile";
  std::string profile_report;
  long long budget = 0;
  std::uint64_t seed = 1;
  std::string cutoff_text, mean_flow_text = "1.74ml/min", period_text = "1s",
              systole_text = "0.3s", inflow_table, venous_text = "10mmHg",
              capillary_drop_text = "5mmHg", external_text = "10mmHg",
              plasma_text = "1mPa s", pries_max_text = "300um", newtonian_text = "3.4mPa s";
  int max_generation = -1;
  long long keep_subtree = -1;
  double hematocrit = 0.45, alpha = 4.0 / 3.0;
  std::string rheology = "pries";

  app.add_option("input", input, "full tree (vnet JSON), - for standard input")->capture_default_str();
  app.add_option("--budget", budget, "number of vessels to keep (the result has it within 1 %)");
  app.add_option("-o,--output", output, "output file, - for standard output")->capture_default_str();
  app.add_option("--format", format_name, "json (vnet), vtk, graphml, dot or csv")->capture_default_str();
  app.add_option("--strategy", strategy, "profile (the paper's), diameter or generation")
      ->capture_default_str();
  app.add_option("--cutoff", cutoff_text, "diameter strategy: keep the daughters of vessels at least this wide");
  app.add_option("--max-generation", max_generation, "generation strategy: keep generations 0..G");
  app.add_option("--keep-subtree", keep_subtree, "keep the subtree below this vessel id complete");
  app.add_option("--seed", seed, "random seed of the selection")->capture_default_str();
  app.add_option("--profile-report", profile_report, "write the full, target and kept profiles (JSON)");
  auto* flow_group = app.add_option_group("inflow");
  flow_group->add_option("--mean-flow", mean_flow_text, "mean inflow of the half-sine wave")->capture_default_str();
  flow_group->add_option("--period", period_text, "cardiac period")->capture_default_str();
  flow_group->add_option("--systole", systole_text, "duration of the half sine")->capture_default_str();
  flow_group->add_option("--inflow-table", inflow_table, "measured inflow: lines of time [s], flow [m^3/s] over one --period");
  auto* blood_group = app.add_option_group("blood and outlets");
  blood_group->add_option("--hematocrit", hematocrit, "discharge hematocrit")->capture_default_str();
  blood_group->add_option("--rheology", rheology, "pries or newtonian")->capture_default_str();
  blood_group->add_option("--plasma-viscosity", plasma_text, "plasma (water) viscosity")->capture_default_str();
  blood_group->add_option("--newtonian-viscosity", newtonian_text, "constant viscosity of --rheology newtonian")->capture_default_str();
  blood_group->add_option("--pries-max-diameter", pries_max_text, "Pries law below this diameter, constant above")->capture_default_str();
  blood_group->add_option("--alpha", alpha, "velocity-profile coefficient (4/3 parabolic)")->capture_default_str();
  blood_group->add_option("--venous-pressure", venous_text, "outflow pressure of every outlet")->capture_default_str();
  blood_group->add_option("--capillary-drop", capillary_drop_text, "mean pressure drop across the capillary outlets")->capture_default_str();
  blood_group->add_option("--external-pressure", external_text, "interstitial pressure for the wall laws")->capture_default_str();
  app.set_version_flag("--version", std::string("vprune ") + HEMOTREE_VERSION);

  return run_tool(app, argc, argv, [&] {
    const auto format = parse_export_format(format_name);
    if (!format) throw InputError("--format: unknown format '" + format_name + "'");
    if (strategy == "profile" && budget < 1)
      throw InputError(budget == 0 ? "--budget is required for the profile strategy"
                                   : "--budget must be at least 1");
    if (strategy == "diameter" && cutoff_text.empty()) throw InputError("--strategy diameter needs --cutoff");
    if (strategy == "generation" && max_generation < 0)
      throw InputError("--strategy generation needs --max-generation >= 0");
    if (strategy != "profile" && strategy != "diameter" && strategy != "generation")
      throw InputError("--strategy must be profile, diameter or generation");

    Blood blood;
    blood.hematocrit = hematocrit;
    blood.alpha = alpha;
    blood.plasma_viscosity = parse_quantity(plasma_text, Dimension::viscosity, "--plasma-viscosity");
    blood.newtonian_viscosity = parse_quantity(newtonian_text, Dimension::viscosity, "--newtonian-viscosity");
    blood.pries_max_diameter = parse_quantity(pries_max_text, Dimension::length, "--pries-max-diameter");
    if (rheology == "newtonian") blood.rheology = Rheology::newtonian;
    else if (rheology != "pries") throw InputError("--rheology must be pries or newtonian");
    blood = blood_from_json(to_json(blood));  // the same checks as a file's "blood"

    const double period = parse_quantity(period_text, Dimension::time, "--period");
    if (!(period > 0)) throw InputError("--period must be positive");
    Waveform wave;
    if (!inflow_table.empty()) {
      wave = read_inflow_table(inflow_table, period);
    } else {
      wave.period = period;
      wave.mean = parse_quantity(mean_flow_text, Dimension::flow, "--mean-flow");
      wave.systole = parse_quantity(systole_text, Dimension::time, "--systole");
      if (!(wave.mean > 0)) throw InputError("--mean-flow must be positive");
      if (!(wave.systole > 0 && wave.systole <= period))
        throw InputError("--systole must lie in (0, --period]");
    }

    OutletParameters outlets;
    outlets.venous_pressure = parse_quantity(venous_text, Dimension::pressure, "--venous-pressure");
    outlets.capillary_pressure_drop = parse_quantity(capillary_drop_text, Dimension::pressure, "--capillary-drop");
    outlets.external_pressure = parse_quantity(external_text, Dimension::pressure, "--external-pressure");

    Network full = read_network(input);
    const std::size_t root = check_rooted_tree(full);
    Inlet inlet;
    inlet.vessel = full.id[root];
    inlet.waveform = wave;
    inlet = inlet_from_json(to_json(inlet));  // the same checks as a file's "inlet"
    full.blood = blood;
    full.inlet = inlet;

    ProfileReport profile;
    KeepMask keep;
    const auto size = static_cast<long long>(full.vessel_count());
    if (strategy == "profile" && budget >= size) {
      note("the budget (" + std::to_string(budget) + ") is not below the tree's " +
           std::to_string(size) + " vessels: keeping every vessel");
      keep.assign(full.vessel_count(), 1);
    } else if (keep_subtree >= 0) {
      keep = prune_keeping_subtree(full, keep_subtree, static_cast<std::size_t>(budget), seed, &profile);
    } else if (strategy == "profile") {
      keep = prune_by_profile(full, static_cast<std::size_t>(budget), seed, &profile);
    } else if (strategy == "diameter") {
      keep = prune_by_diameter(full, parse_quantity(cutoff_text, Dimension::length, "--cutoff"));
    } else {
      keep = prune_by_generation(full, max_generation);
    }

    Network pruned = extract(full, keep);
    const OutletReport report = calibrate_outlets(full, keep, pruned, outlets);
    const double full_p = report.steady_inlet_pressure_full;
    const double pruned_p = report.steady_inlet_pressure_pruned;
    const double mismatch = std::abs(pruned_p - full_p) / full_p;
    note("kept " + std::to_string(pruned.vessel_count()) + " of " + std::to_string(size) +
         " vessels; outlets: " + std::to_string(report.rcr) + " RCR, " +
         std::to_string(report.resistance) + " R, " + std::to_string(report.leaf) +
         " capillary; steady inlet pressure " + mmhg(pruned_p) + " (full tree " + mmhg(full_p) + ")");
    if (!(mismatch <= 1e-3))
      throw std::logic_error("the outlets do not reproduce the full tree's steady inlet pressure (" +
                             mmhg(pruned_p) + " against " + mmhg(full_p) + ")");

    nlohmann::json parameters = {{"strategy", strategy}, {"seed", seed}, {"outlets",
        {{"venous_pressure", outlets.venous_pressure},
         {"capillary_pressure_drop", outlets.capillary_pressure_drop},
         {"external_pressure", outlets.external_pressure},
         {"rcr_min_diameter", outlets.rcr_min_diameter},
         {"thick_wall_ratio", outlets.thick_wall_ratio}}}};
    if (budget > 0) parameters["budget"] = budget;
    if (!cutoff_text.empty()) parameters["cutoff"] = parse_quantity(cutoff_text, Dimension::length, "--cutoff");
    if (max_generation >= 0) parameters["max_generation"] = max_generation;
    if (keep_subtree >= 0) parameters["keep_subtree"] = keep_subtree;
    nlohmann::json provenance = {{"tool", "vprune"}, {"version", HEMOTREE_VERSION},
                                 {"parameters", parameters}, {"source", full.provenance}};
    provenance.update(to_json(report));
    pruned.provenance = provenance;

    if (!profile_report.empty()) {
      OutputStream report_out(profile_report);
      report_out << to_json(profile).dump(1) << '\n';
      report_out.commit();
    }
    OutputStream out(output);
    write_network_as(pruned, *format, out);
    out.commit();
    return 0;
  });
}
