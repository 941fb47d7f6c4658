// The growth rules file (vgen --rules) on hostile bytes, through read_rules as vgen calls it.
// Rules it accepts must print and read back the same (vgen --print-rules), give finite,
// positive wall thicknesses and moduli inside their ranges, and grow a small tree that the
// network writer writes (and the reader reads or refuses with one of the project's errors).
#include <cmath>
#include <cstdint>
#include <string>

#include <omp.h>

#include "formats/network_io.hpp"
#include "fuzz_support.hpp"
#include "generator/growth_rules.hpp"
#include "generator/size_estimate.hpp"
#include "generator/tree_growth.hpp"

using namespace hemotree;
using hemotree::fuzz::finding;

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  fuzz::keep_report_channel();
  omp_set_num_threads(1);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = fuzz::scratch() / "rules.json";
  fuzz::write_file(path, std::string_view(reinterpret_cast<const char*>(data), size));
  auto rules_result = fuzz::outcome("read_rules", [&] { return read_rules(path.string()); });
  auto& rules = rules_result.first;
  if (!rules) return 0;

  const nlohmann::json printed = to_json(*rules);
  auto again_result = fuzz::outcome("rules_from_json(to_json)", [&] { return rules_from_json(printed); });
  auto& again = again_result.first;
  auto& again_error = again_result.second;
  if (!again) finding("--print-rules prints rules that --rules refuses: " + again_error.message);
  if (to_json(*again) != printed) finding("rules printed and read back differ");

  // Every diameter the rules cover: a range, a modulus and wall thicknesses fit for a vessel.
  for (const BranchingRange& range : rules->ranges)
    for (const double d : {range.diameter_min, 0.5 * (range.diameter_min + range.diameter_max)}) {
      if (!(d > 0)) continue;
      auto found_result = fuzz::outcome("range_for", [&] { return &rules->range_for(d); });
      auto& found = found_result.first;
      auto& outside = found_result.second;
      if (!found) finding("range_for(" + std::to_string(d) + ") inside the ranges: " + outside.message);
      const double e = rules->youngs_modulus(d);
      if (!(std::isfinite(e) && e > 0)) finding("accepted rules give E = " + std::to_string(e));
      const double h = rules->wall[static_cast<int>(classify(d))].thickness(d);
      if (!(std::isfinite(h) && h > 0))
        finding("accepted rules give a wall thickness of " + std::to_string(h) + " m at D = " + std::to_string(d));
    }

  // A small tree from the top of the widest range down to half its diameter, when the
  // estimate says it is small: it must write, and read back or be refused.
  const BranchingRange& top = rules->ranges.back();
  GrowthParameters p;
  p.root_diameter = std::nextafter(top.diameter_max, 0.0);
  p.min_diameter = 0.5 * p.root_diameter;
  if (!(p.min_diameter > 0)) return 0;
  auto [expected, estimate_error] =
      fuzz::outcome("expected_vessel_count", [&] { return expected_vessel_count(*rules, p); });
  if (!expected || !(*expected >= 1 && *expected < 2000)) return 0;
  auto tree_result = fuzz::outcome("grow_tree", [&] { return grow_tree(*rules, p); });
  auto& tree = tree_result.first;
  if (!tree) return 0;
  if (static_cast<double>(tree->vessel_count()) > 100 * *expected + 100)
    finding("the estimate said " + std::to_string(*expected) + " vessels, the tree has " +
            std::to_string(tree->vessel_count()));
  const auto net_path = fuzz::scratch() / "tree.json";
  auto written_result = fuzz::outcome("write_network", [&] {
    OutputStream out(net_path.string());
    write_network(*tree, out);
    out.commit();
    return true;
  });
  auto& written = written_result.first;
  auto& write_error = written_result.second;
  if (!written) finding("write_network refuses a tree grown by accepted rules: " + write_error.message);
  // The reader may refuse it with one of the project's errors (a length below its range, from a
  // calibration that is valid but absurd): vgen checks the tree it grew the same way, exit 2.
  fuzz::outcome("read_network", [&] { return read_network(net_path.string()); });
  return 0;
}
