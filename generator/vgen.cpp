// vgen: grows a statistically calibrated full vascular tree and writes it as a network.
#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>

#include <CLI/CLI.hpp>

#include "core/errors.hpp"
#include "cli/progress.hpp"
#include "cli/setting_words.hpp"
#include "cli/tool.hpp"
#include "core/units.hpp"
#include "formats/exports.hpp"
#include "formats/field_ranges.hpp"
#include "formats/network_io.hpp"
#include "generator/growth_rules.hpp"
#include "generator/size_estimate.hpp"
#include "generator/tree_growth.hpp"
#include "generator/tree_layout.hpp"
#include "generator/venous_mirror.hpp"

using namespace hemotree;

namespace {

// Below 3 um no red cell passes (the narrowest capillaries measured are about 3 um), and the
// last daughters, up to 23 % thinner than --min-diameter under the default stop rule, would
// fall below the 2 um the network format accepts.
constexpr double lowest_min_diameter = 3e-6;

// Every vessel within the ranges the reader accepts, so that what vgen writes reads back;
// only a rules file can grow one outside them.
void check_fields(const Network& net) {
  auto check = [&](const std::vector<double>& values, std::string_view field,
                   const FieldRange& range) {
    for (std::size_t v = 0; v < values.size(); ++v)
      if (!range.contains(values[v]))
        throw InputError("the growth rules give vessel " + std::to_string(net.id[v]) + " " +
                         out_of_range(field, range, values[v]) +
                         ": change the rules or --min-diameter");
  };
  check(net.diameter, "diameter", ranges::diameter);
  check(net.length, "length", ranges::length);
  check(net.wall_thickness, "wall_thickness", ranges::wall_thickness);
  check(net.youngs_modulus, "youngs_modulus", ranges::youngs_modulus);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Grow a full vascular tree by stochastic branching (Murray's law, fractal "
               "length law) and write it in the vnet network format.",
               "vgen"};
  std::string root_text = "1mm", min_text = "7um", rules_path, output = "-", format_name;
  std::string seed_text = "1", mean_flow_text = "1.74ml/min", venous_pressure_text = "10mmHg",
              venous_ratio_text = "1";
  bool print_rules = false, force = false, venous = false;
  app.add_option("--root-diameter", root_text,
                 "diameter of the root vessel, SI metres or with a unit (1mm); in [3um, 2.6cm) "
                 "with the default rules (their largest diameter), above --min-diameter")
      ->capture_default_str();
  app.add_option("--min-diameter", min_text,
                 "where growth stops: a vessel branches only if its daughters' mean diameter "
                 "would be at least this (the rules' stop rule, mean_daughter by default), so "
                 "the thinner daughters of the last branchings lie below it (down to 5.4um for "
                 "7um); at least 3um and below --root-diameter")
      ->capture_default_str();
  app.add_option("--seed", seed_text,
                 "random seed, an integer in 0..18446744073709551615; the same seed gives "
                 "byte-identical output")
      ->capture_default_str();
  app.add_option("--rules", rules_path, "growth rules (JSON, the form --print-rules prints)");
  app.add_flag("--print-rules", print_rules, "print the growth rules in use (to -o) and exit");
  app.add_option("-o,--output", output, "output file, - for standard output")->capture_default_str();
  app.add_option("--format", format_name,
                 "json or h5 (vnet), vtk, graphml, dot or csv (default: h5 for a -o file named *.h5, else json)");
  app.add_flag("--force", force,
               "grow even when the estimated size exceeds available memory (never beyond the "
               "2147483646 vessels a network holds)");
  app.add_flag("--venous", venous,
               "add the tree's venous mirror: each vessel a venous twin carrying its flow back, the capillaries "
               "joining the two trees (arterio-venous loops), a flow boundary at the arterial root and a "
               "pressure boundary at the venous root (format version 2; hemosolve --steady runs it)")
      ->group("Venous mirror");
  app.add_option("--mean-flow", mean_flow_text, "with --venous: the inflow at the arterial root")
      ->capture_default_str()
      ->group("Venous mirror");
  app.add_option("--venous-pressure", venous_pressure_text, "with --venous: the pressure at the venous root")
      ->capture_default_str()
      ->group("Venous mirror");
  app.add_option("--venous-diameter-ratio", venous_ratio_text,
                 "with --venous: a venous twin's diameter (and wall) over its artery's, in [0.5, 4]")
      ->capture_default_str()
      ->group("Venous mirror");
  app.set_version_flag("--version", std::string("vgen ") + HEMOTREE_VERSION);

  const int status = run_tool(app, argc, argv, vgen_words(), [&] {
    const GrowthRules rules = rules_path.empty() ? default_rules() : read_rules(rules_path);
    if (print_rules) {
      OutputStream out(output);
      out << to_json(rules).dump(2) << '\n';
      out.commit();
      return 0;
    }
    const ExportFormat format = output_format(format_name, output);
    GrowthParameters p;
    p.seed = parse_count(seed_text, "--seed", 0, std::numeric_limits<std::uint64_t>::max());
    // The rules' ranges are sorted and contiguous: together they cover [front.min, back.max).
    const double rules_top = rules.ranges.back().diameter_max;
    const double lowest = std::max(lowest_min_diameter, rules.ranges.front().diameter_min);
    p.min_diameter = parse_quantity(min_text, Dimension::length, "--min-diameter",
                                    Interval{lowest, rules_top, false, true}, "um");
    p.root_diameter = parse_quantity(root_text, Dimension::length, "--root-diameter",
                                     Interval{lowest, rules_top, false, true}, "mm");
    if (!(p.min_diameter < p.root_diameter))
      throw InputError("--min-diameter (" + min_text + ") must be below --root-diameter (" +
                       root_text + ")");

    // Refuse before growing when the tree cannot fit: a million-fold mistake in a unit
    // should cost a second, not an out-of-memory kill after minutes.
    const double expected = expected_vessel_count(rules, p);
    const double needed = expected * vgen_bytes_per_vessel;
    const double available = available_memory_bytes();
    if (!(expected <= static_cast<double>(max_grown_vessels)))
      throw InputError("the tree would have about " + format_rounded(expected) +
                       " vessels, more than the " + std::to_string(max_grown_vessels) +
                       " a network holds (even with --force): raise --min-diameter or lower "
                       "--root-diameter");
    if (!force && available > 0 && needed > available)
      throw InputError("the tree would have about " + format_rounded(expected) +
                       " vessels and need " + format_rounded(needed / 1e9) +
                       " GB of memory, more than the " + format_rounded(available / 1e9) +
                       " GB available (use --force to try anyway)");

    Progress progress("vgen: growing", static_cast<std::size_t>(expected));
    Network net = grow_tree(rules, p, static_cast<std::size_t>(expected * 1.05),
                            [&](std::size_t done) { progress.update(done); });
    progress.finish();
    check_fields(net);
    lay_out_tree(net);
    nlohmann::json venous_parameters;
    if (venous) {
      VenousMirror mirror;
      mirror.mean_flow = parse_quantity(mean_flow_text, Dimension::flow, "--mean-flow",
                                        Interval{ranges::mean_flow.min, ranges::mean_flow.max}, "ml/min");
      mirror.venous_pressure = parse_quantity(venous_pressure_text, Dimension::pressure, "--venous-pressure",
                                              Interval{ranges::pressure.min, ranges::pressure.max}, "mmHg");
      mirror.diameter_ratio = parse_number(venous_ratio_text, "--venous-diameter-ratio", Interval{0.5, 4});
      mirror.offset = 2 * p.root_diameter;
      add_venous_mirror(net, mirror);
      check_fields(net);
      venous_parameters = {{"mean_flow", mirror.mean_flow},
                           {"venous_pressure", mirror.venous_pressure},
                           {"diameter_ratio", mirror.diameter_ratio}};
    } else if (app.count("--mean-flow") + app.count("--venous-pressure") + app.count("--venous-diameter-ratio") > 0) {
      throw InputError("--mean-flow, --venous-pressure and --venous-diameter-ratio apply with --venous only");
    }
    net.provenance = {{"tool", "vgen"},
                      {"version", HEMOTREE_VERSION},
                      {"seed", p.seed},
                      {"parameters",
                       {{"root_diameter", p.root_diameter},
                        {"min_diameter", p.min_diameter},
                        {"rules", to_json(rules)}}}};
    if (venous) net.provenance["parameters"]["venous"] = venous_parameters;

    OutputStream out(output);
    write_network_as(net, format, out);
    out.commit();
    return 0;
  });
  // --help and --version print outside any OutputStream: a full disk must not pass for them.
  if (status == 0) {
    if (const std::string why = standard_output_error(); !why.empty()) {
      std::fprintf(stderr, "vgen: error: cannot write standard output: %s\n", why.c_str());
      return 1;
    }
  }
  return status;
}
