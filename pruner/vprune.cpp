// vprune: cuts a full tree to a computational budget and replaces every removed subtree by
// an outlet calibrated from it, so the pruned network runs as it is in hemosolve.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "core/errors.hpp"
#include "cli/setting_words.hpp"
#include "cli/tool.hpp"
#include "core/units.hpp"
#include "formats/exports.hpp"
#include "formats/field_ranges.hpp"
#include "formats/network_io.hpp"
#include "formats/topology.hpp"
#include "pruner/outlet_calibration.hpp"
#include "pruner/pruning_strategies.hpp"

using namespace hemotree;

namespace {

// The flags that make a network's blood and inlet accept what the reader accepts in a file
// (formats/field_ranges.hpp), so that vprune never writes what hemosolve then refuses.
Interval accepted(const FieldRange& r) { return Interval{r.min, r.max}; }

// What --help says of a range: "in [0.01, 100] s".
std::string in(const FieldRange& r, std::string_view unit) {
  return "in " + describe(accepted(r), unit);
}

// A measured inflow: two columns, time [s] and flow [m^3/s], comma or space separated,
// '#' comments; the period is given separately. Every row is checked here, by line.
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
    const std::string where = "--inflow-table " + path + ":" + std::to_string(number);
    if (auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    for (char& c : line)
      if (c == ',' || c == ';' || c == '\t' || c == '\r') c = ' ';
    std::istringstream fields(line);
    std::string t_text, q_text, extra;
    if (!(fields >> t_text)) continue;  // blank line
    if (!(fields >> q_text) || (fields >> extra))
      throw InputError(where + ": expected two numbers (time [s], flow [m^3/s])");
    const double t = parse_quantity(t_text, Dimension::dimensionless, where + ": time",
                                    Interval{0, period, false, true}, "s");
    const double q = parse_quantity(q_text, Dimension::dimensionless, where + ": flow",
                                    accepted(ranges::flow_sample), "m^3/s");
    if (!w.time.empty() && !(t > w.time.back()))
      throw InputError(where + ": times must increase (" + t_text + " s follows " +
                       format_rounded(w.time.back()) + " s)");
    w.time.push_back(t);
    w.value.push_back(q);
  }
  if (w.time.size() < 2) throw InputError("--inflow-table " + path + ": needs at least two rows");
  const double mean = w.mean_value();
  if (!ranges::mean_flow.contains(mean))
    throw InputError("--inflow-table " + path + ": the mean flow " +
                     format_quantity(mean, "ml/min") + " lies outside the accepted range " +
                     describe(accepted(ranges::mean_flow), "ml/min"));
  return w;
}

// Every calibrated outlet within what the reader accepts: extreme but accepted flags (a tiny
// inflow over a large tree) could otherwise give resistances beyond them.
void check_outlets(const Network& pruned) {
  for (const Outlet& o : pruned.outlets) {
    const std::string where = "the calibrated outlet of vessel " +
                              std::to_string(pruned.id[static_cast<std::size_t>(o.vessel)]) + ": ";
    auto check = [&](std::string_view field, const FieldRange& range, double value) {
      if (!range.contains(value))
        throw InputError(where + out_of_range(field, range, value) +
                         " (--mean-flow or --capillary-drop out of proportion for this tree)");
    };
    if (o.type == BoundaryType::rcr) {
      check("R1", ranges::rcr_part, o.r1);
      check("R2", ranges::rcr_part, o.r2);
      check("C", ranges::compliance, o.c);
    } else if (o.type == BoundaryType::resistance) {
      check("R", ranges::resistance, o.r);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Cut a full vascular tree to a computational budget and replace each removed "
               "subtree by a calibrated RCR or R outlet.",
               "vprune"};
  std::string input = "-", output = "-", format_name, strategy = "profile";
  std::string profile_report;
  std::string budget_text, seed_text = "1", max_generation_text, keep_subtree_text;
  std::string cutoff_text, mean_flow_text = "1.74ml/min", period_text = "1s",
              systole_text = "0.3s", inflow_table, venous_text = "10mmHg",
              capillary_drop_text = "5mmHg", external_text = "10mmHg",
              plasma_text = "1mPa s", pries_max_text = "300um", newtonian_text = "3.4mPa s";
  std::string hematocrit_text = "0.45", alpha_text;  // alpha: 4/3 unless given
  std::string rheology = "pries";
  const std::string int64_max = std::to_string(std::numeric_limits<std::int64_t>::max());

  app.add_option("input", input, "full tree (vnet JSON), - for standard input")->capture_default_str();
  app.add_option("--budget", budget_text,
                 "profile strategy: number of vessels to keep, an integer in 1.." + int64_max +
                     " (the result has it within 1 %), or all: the whole tree, its leaves' outlets "
                     "calibrated (as any budget of at least the tree's size)");
  app.add_option("-o,--output", output, "output file, - for standard output")->capture_default_str();
  app.add_option("--format", format_name,
                 "json or h5 (vnet), vtk, graphml, dot or csv (default: h5 for a -o file named *.h5, else json)");
  app.add_option("--strategy", strategy, "profile (the paper's), diameter or generation")
      ->capture_default_str();
  app.add_option("--cutoff", cutoff_text,
                 "diameter strategy: keep the daughters of vessels at least this wide, " +
                     in(ranges::diameter, "um"));
  app.add_option("--max-generation", max_generation_text,
                 "generation strategy: keep generations 0..G, G an integer in 0.." +
                     std::to_string(ranges::max_generation));
  app.add_option("--keep-subtree", keep_subtree_text,
                 "profile strategy: keep the subtree below this vessel id (an integer) complete");
  app.add_option("--seed", seed_text,
                 "random seed of the selection, an integer in 0..18446744073709551615")
      ->capture_default_str();
  app.add_option("--profile-report", profile_report, "write the full, target and kept profiles (JSON)");
  // Help sections by Option::group, not add_option_group: CLI11 2.1 takes an empty argument
  // for the name of an option group (they have none) and loops forever ('vprune x "" --budget 5').
  auto* mean_flow_option = app.add_option("--mean-flow", mean_flow_text,
      "mean inflow of the half-sine wave, " + in(ranges::mean_flow, "ml/min") +
          "; the steady pressures scale with it, so it must suit the tree's size")
      ->capture_default_str()
      ->group("Inflow");
  app.add_option("--period", period_text, "cardiac period, " + in(ranges::period, "s"))
      ->capture_default_str()
      ->group("Inflow");
  auto* systole_option = app.add_option("--systole", systole_text,
      "duration of the half sine, " + in(ranges::systole, "s") + " and at most --period")
      ->capture_default_str()
      ->group("Inflow");
  app.add_option("--inflow-table", inflow_table,
      "measured inflow instead of the half sine: lines of time [s] in [0, --period), "
      "increasing, and flow [m^3/s] " + in(ranges::flow_sample, "m^3/s") + ", with a mean " +
          in(ranges::mean_flow, "ml/min"))
      ->group("Inflow");
  app.add_option("--hematocrit", hematocrit_text,
                          "discharge hematocrit, " + in(ranges::hematocrit, ""))
      ->capture_default_str()
      ->group("Blood and outlets");
  app.add_option("--rheology", rheology, "pries or newtonian")->capture_default_str()
      ->group("Blood and outlets");
  app.add_option("--plasma-viscosity", plasma_text,
                          "plasma (water) viscosity, " + in(ranges::viscosity, "mPa s"))
      ->capture_default_str()
      ->group("Blood and outlets");
  app.add_option("--newtonian-viscosity", newtonian_text,
                          "constant viscosity of --rheology newtonian, " +
                              in(ranges::viscosity, "mPa s"))
      ->capture_default_str()
      ->group("Blood and outlets");
  app.add_option("--pries-max-diameter", pries_max_text,
                          "Pries law below this diameter, constant above, " +
                              in(ranges::pries_max_diameter, "um"))
      ->capture_default_str()
      ->group("Blood and outlets");
  app.add_option("--alpha", alpha_text,
                          "velocity-profile coefficient, " + in(ranges::alpha, "") +
                              " (default 4/3, a parabolic profile)")
      ->group("Blood and outlets");
  app.add_option("--venous-pressure", venous_text,
                          "outflow pressure of every outlet, " + in(ranges::pressure, "mmHg"))
      ->capture_default_str()
      ->group("Blood and outlets");
  app.add_option("--capillary-drop", capillary_drop_text,
                          "mean pressure drop across the capillary outlets, in " +
                              describe(Interval{0, ranges::pressure.max, true, false}, "mmHg"))
      ->capture_default_str()
      ->group("Blood and outlets");
  app.add_option("--external-pressure", external_text,
                          "interstitial pressure for the wall laws, " + in(ranges::pressure, "mmHg"))
      ->capture_default_str()
      ->group("Blood and outlets");
  app.set_version_flag("--version", std::string("vprune ") + HEMOTREE_VERSION);

  const int status = run_tool(app, argc, argv, vprune_words(), [&] {
    // ---- every flag, before any work ---------------------------------------------------
    const ExportFormat format = output_format(format_name, output);
    if (strategy != "profile" && strategy != "diameter" && strategy != "generation")
      throw InputError("--strategy must be profile, diameter or generation");
    // A flag of another strategy would be ignored: say so rather than run without it.
    auto only_for = [&](const std::string& text, const char* flag, const char* wanted) {
      if (!text.empty() && strategy != wanted)
        throw InputError(std::string(flag) + " applies to --strategy " + wanted + " only");
    };
    only_for(budget_text, "--budget", "profile");
    only_for(keep_subtree_text, "--keep-subtree", "profile");
    only_for(cutoff_text, "--cutoff", "diameter");
    only_for(max_generation_text, "--max-generation", "generation");
    if (strategy == "profile" && budget_text.empty())
      throw InputError("--budget is required for the profile strategy");
    if (strategy == "diameter" && cutoff_text.empty()) throw InputError("--strategy diameter needs --cutoff");
    if (strategy == "generation" && max_generation_text.empty())
      throw InputError("--strategy generation needs --max-generation");

    const bool budget_all = budget_text == "all";
    const long long budget =
        budget_text.empty() ? 0
        : budget_all        ? std::numeric_limits<std::int64_t>::max()
                            : static_cast<long long>(parse_count(
                                  budget_text, "--budget", 1, std::numeric_limits<std::int64_t>::max()));
    const int max_generation =
        max_generation_text.empty()
            ? -1
            : static_cast<int>(parse_count(max_generation_text, "--max-generation", 0,
                                           static_cast<std::uint64_t>(ranges::max_generation)));
    const bool keep_subtree = !keep_subtree_text.empty();
    const std::int64_t subtree_id =
        keep_subtree ? parse_integer(keep_subtree_text, "--keep-subtree",
                                     std::numeric_limits<std::int64_t>::min(),
                                     std::numeric_limits<std::int64_t>::max())
                     : 0;
    const std::uint64_t seed =
        parse_count(seed_text, "--seed", 0, std::numeric_limits<std::uint64_t>::max());
    const double cutoff =
        cutoff_text.empty() ? 0
                            : parse_quantity(cutoff_text, Dimension::length, "--cutoff",
                                             accepted(ranges::diameter), "um");

    Blood blood;
    blood.hematocrit = parse_number(hematocrit_text, "--hematocrit", accepted(ranges::hematocrit));
    if (!alpha_text.empty()) blood.alpha = parse_number(alpha_text, "--alpha", accepted(ranges::alpha));
    blood.plasma_viscosity = parse_quantity(plasma_text, Dimension::viscosity, "--plasma-viscosity",
                                            accepted(ranges::viscosity), "mPa s");
    blood.newtonian_viscosity =
        parse_quantity(newtonian_text, Dimension::viscosity, "--newtonian-viscosity",
                       accepted(ranges::viscosity), "mPa s");
    blood.pries_max_diameter =
        parse_quantity(pries_max_text, Dimension::length, "--pries-max-diameter",
                       accepted(ranges::pries_max_diameter), "um");
    const std::optional<Rheology> law = rheology_of(rheology);
    if (!law) throw InputError("--rheology must be pries or newtonian");
    blood.rheology = *law;
    blood = blood_from_json(to_json(blood));  // the same checks as a file's "blood"

    const double period = parse_quantity(period_text, Dimension::time, "--period",
                                         accepted(ranges::period), "s");
    Waveform wave;
    if (!inflow_table.empty()) {
      if (mean_flow_option->count() || systole_option->count())
        throw InputError("--inflow-table replaces the half sine: give it without --mean-flow and --systole");
      wave = read_inflow_table(inflow_table, period);
    } else {
      wave.period = period;
      wave.mean = parse_quantity(mean_flow_text, Dimension::flow, "--mean-flow",
                                 accepted(ranges::mean_flow), "ml/min");
      Interval systole = accepted(ranges::systole);
      systole.max = std::min(systole.max, period);
      wave.systole = parse_quantity(systole_text, Dimension::time, "--systole", systole, "s");
    }

    OutletParameters outlets;
    outlets.venous_pressure = parse_quantity(venous_text, Dimension::pressure, "--venous-pressure",
                                             accepted(ranges::pressure), "mmHg");
    outlets.capillary_pressure_drop =
        parse_quantity(capillary_drop_text, Dimension::pressure, "--capillary-drop",
                       Interval{0, ranges::pressure.max, true, false}, "mmHg");
    outlets.external_pressure = parse_quantity(external_text, Dimension::pressure,
                                               "--external-pressure", accepted(ranges::pressure), "mmHg");

    // ---- the tree and its pruning --------------------------------------------------------
    Network full = read_network(input);
    std::size_t root = 0;
    try {
      root = check_rooted_tree(full);
    } catch (const InputError& e) {
      throw InputError(std::string(e.what()) + ": vprune cuts trees (hemosolve --steady solves any network whole)");
    }
    // vprune sets the tree's boundaries itself: an inflow at its root and calibrated outlets.
    if (!full.boundaries.empty() || full.inlet || !full.outlets.empty()) {
      note("note: the file's boundary conditions (" + std::to_string(node_boundaries(full).size()) +
           ") are replaced by the inflow at the root and the calibrated outlets");
      full.boundaries.clear();
      full.outlets.clear();
    }
    Inlet inlet;
    inlet.vessel = full.id[root];
    inlet.waveform = wave;
    inlet = inlet_from_json(to_json(inlet));  // the same checks as a file's "inlet"
    full.blood = blood;
    full.inlet = inlet;

    ProfileReport profile;
    KeepMask keep;
    const auto size = static_cast<long long>(full.vessel_count());
    bool keeping_all = false;
    if (strategy == "profile" && budget >= size) {
      keeping_all = true;
      keep.assign(full.vessel_count(), 1);
    } else if (keep_subtree) {
      keep = prune_keeping_subtree(full, subtree_id, static_cast<std::size_t>(budget), seed, &profile);
    } else if (strategy == "profile") {
      keep = prune_by_profile(full, static_cast<std::size_t>(budget), seed, &profile);
    } else if (strategy == "diameter") {
      keep = prune_by_diameter(full, cutoff);
    } else {
      keep = prune_by_generation(full, max_generation);
    }

    Network pruned = extract(full, keep);
    const OutletReport report = calibrate_outlets(full, keep, pruned, outlets);
    const double full_p = report.steady_inlet_pressure_full;
    const double pruned_p = report.steady_inlet_pressure_pruned;

    // ---- every check of the result, before anything is said or written -------------------
    if (!std::isfinite(full_p) || !std::isfinite(pruned_p))
      throw InputError("the steady flow of this tree has no finite inlet pressure: check "
                       "--mean-flow and the vessels' lengths and diameters");
    check_outlets(pruned);
    if (!(std::abs(pruned_p - full_p) <= 1e-3 * std::abs(full_p)))
      throw std::logic_error("the outlets do not reproduce the full tree's steady inlet pressure (" +
                             format_quantity(pruned_p, "mmHg") + " against " +
                             format_quantity(full_p, "mmHg") + ")");

    nlohmann::json parameters = {{"strategy", strategy}, {"seed", seed}, {"outlets",
        {{"venous_pressure", outlets.venous_pressure},
         {"capillary_pressure_drop", outlets.capillary_pressure_drop},
         {"external_pressure", outlets.external_pressure},
         {"rcr_min_diameter", outlets.rcr_min_diameter},
         {"thick_wall_ratio", outlets.thick_wall_ratio}}}};
    if (budget_all) parameters["budget"] = "all";
    else if (budget > 0) parameters["budget"] = budget;
    if (!cutoff_text.empty()) parameters["cutoff"] = cutoff;
    if (max_generation >= 0) parameters["max_generation"] = max_generation;
    if (keep_subtree) parameters["keep_subtree"] = subtree_id;
    nlohmann::json provenance = {{"tool", "vprune"}, {"version", HEMOTREE_VERSION},
                                 {"parameters", parameters}, {"source", full.provenance}};
    provenance.update(to_json(report));
    try {
      (void)provenance.dump();  // the writer's own serialization, tried before anything is said
    } catch (const nlohmann::json::exception&) {
      throw InputError("the input's provenance holds a string that is not valid UTF-8");
    }
    pruned.provenance = provenance;

    if (keeping_all && budget_all)
      note("--budget all: keeping every one of the tree's " + std::to_string(size) + " vessels");
    else if (keeping_all)
      note("the budget (" + std::to_string(budget) + ") is not below the tree's " +
           std::to_string(size) + " vessels: keeping every vessel");
    note("kept " + std::to_string(pruned.vessel_count()) + " of " + std::to_string(size) +
         " vessels; outlets: " + std::to_string(report.rcr) + " RCR, " +
         std::to_string(report.resistance) + " R, " + std::to_string(report.leaf) +
         " capillary; steady inlet pressure " + format_quantity(pruned_p, "mmHg") +
         " (full tree " + format_quantity(full_p, "mmHg") + ")");
    if (const std::string w = unphysiological_pressure_warning(
            report, outlets, full.inlet->waveform.mean_value(), full.diameter[root], vprune_words());
        !w.empty())
      warn(w);

    if (!profile_report.empty()) {
      OutputStream report_out(profile_report);
      report_out << to_json(profile).dump(1) << '\n';
      report_out.commit();
    }
    OutputStream out(output);
    write_network_as(pruned, format, out);
    out.commit();
    return 0;
  });
  // --help and --version print outside any OutputStream: a full disk must not pass for them.
  if (status == 0) {
    if (const std::string why = standard_output_error(); !why.empty()) {
      std::fprintf(stderr, "vprune: error: cannot write standard output: %s\n", why.c_str());
      return 1;
    }
  }
  return status;
}
