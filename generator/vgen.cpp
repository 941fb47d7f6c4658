// vgen: grows a statistically calibrated full vascular tree and writes it as a network.
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>

#include <CLI/CLI.hpp>

#include "cli/errors.hpp"
#include "cli/progress.hpp"
#include "cli/tool.hpp"
#include "cli/units.hpp"
#include "formats/exports.hpp"
#include "formats/network_io.hpp"
#include "generator/growth_rules.hpp"
#include "generator/size_estimate.hpp"
#include "generator/tree_growth.hpp"
#include "generator/tree_layout.hpp"

using namespace hemotree;

int main(int argc, char** argv) {
  CLI::App app{"Grow a full vascular tree by stochastic branching (Murray's law, fractal "
               "length law) and write it in the vnet network format.",
               "vgen"};
  std::string root_text = "1mm", min_text = "7um", rules_path, output = "-", format_name = "json";
  std::uint64_t seed = 1;
  bool print_rules = false, force = false;
  app.add_option("--root-diameter", root_text, "root vessel diameter (SI metres or with a unit: 1mm)")
      ->capture_default_str();
  app.add_option("--min-diameter", min_text, "smallest diameter grown (7um)")->capture_default_str();
  app.add_option("--seed", seed, "random seed; the same seed gives byte-identical output")
      ->capture_default_str();
  app.add_option("--rules", rules_path, "growth rules (JSON, the form --print-rules prints)");
  app.add_flag("--print-rules", print_rules, "print the growth rules in use and exit");
  app.add_option("-o,--output", output, "output file, - for standard output")->capture_default_str();
  app.add_option("--format", format_name, "json (vnet), vtk, graphml, dot or csv")
      ->capture_default_str();
  app.add_flag("--force", force, "grow even when the estimated size exceeds available memory");
  app.set_version_flag("--version", std::string("vgen ") + HEMOTREE_VERSION);

  return run_tool(app, argc, argv, [&] {
    const GrowthRules rules = rules_path.empty() ? default_rules() : read_rules(rules_path);
    if (print_rules) {
      std::cout << to_json(rules).dump(2) << '\n';
      return 0;
    }
    const auto format = parse_export_format(format_name);
    if (!format) throw InputError("--format: unknown format '" + format_name + "'");
    GrowthParameters p;
    p.root_diameter = parse_quantity(root_text, Dimension::length, "--root-diameter");
    p.min_diameter = parse_quantity(min_text, Dimension::length, "--min-diameter");
    p.seed = seed;
    if (!(p.root_diameter > 0)) throw InputError("--root-diameter must be positive");
    if (!(p.min_diameter > 0)) throw InputError("--min-diameter must be positive");
    if (!(p.min_diameter < p.root_diameter))
      throw InputError("--min-diameter (" + min_text + ") must be below --root-diameter (" +
                       root_text + ")");

    // Refuse before growing when the tree cannot fit: a million-fold mistake in a unit
    // should cost a second, not an out-of-memory kill after minutes.
    const double expected = expected_vessel_count(rules, p);
    const double needed = expected * vgen_bytes_per_vessel;
    const double available = available_memory_bytes();
    if (!force && (expected > 2e9 || (available > 0 && needed > available))) {
      std::ostringstream m;
      m << "the tree would have about " << static_cast<long long>(expected) << " vessels and need "
        << needed / 1e9 << " GB of memory, more than the " << available / 1e9
        << " GB available (use --force to try anyway)";
      throw InputError(m.str());
    }

    Progress progress("vgen: growing", static_cast<std::size_t>(expected));
    Network net = grow_tree(rules, p, static_cast<std::size_t>(expected * 1.05),
                            [&](std::size_t done) { progress.update(done); });
    progress.finish();
    lay_out_tree(net);
    net.provenance = {{"tool", "vgen"},
                      {"version", HEMOTREE_VERSION},
                      {"seed", p.seed},
                      {"parameters",
                       {{"root_diameter", p.root_diameter},
                        {"min_diameter", p.min_diameter},
                        {"rules", to_json(rules)}}}};

    OutputStream out(output);
    write_network_as(net, *format, out);
    out.commit();
    return 0;
  });
}
