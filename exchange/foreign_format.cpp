#include "exchange/foreign_format.hpp"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>

#include "cli/errors.hpp"
#include "formats/field_ranges.hpp"
#include "generator/growth_rules.hpp"

namespace hemotree {

std::string read_whole_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError("cannot open " + path + ": " + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw IoError("cannot read " + path);
  return std::move(text).str();
}

void fill_missing_walls(Network& net, const ImportOptions& options) {
  const GrowthRules rules = default_rules();
  std::size_t walls = 0, moduli = 0;
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    const double d = net.diameter[v];
    if (std::isnan(net.wall_thickness[v])) {
      net.wall_thickness[v] = options.wall_ratio
                                  ? *options.wall_ratio * d
                                  : rules.wall[static_cast<std::size_t>(classify(d))].thickness(d);
      ++walls;
    }
    if (std::isnan(net.youngs_modulus[v])) {
      net.youngs_modulus[v] = options.youngs_modulus ? *options.youngs_modulus : rules.youngs_modulus(d);
      ++moduli;
    }
  }
  const auto count = [](std::size_t n) { return std::to_string(n) + (n == 1 ? " vessel" : " vessels"); };
  if (walls > 0)
    options.note(options.wall_ratio
                     ? "wall thickness h = " + format_number(*options.wall_ratio) + " D for " + count(walls) +
                           " (--wall-ratio)"
                     : "wall thickness from hemotree's per-class wall law (vgen --print-rules) for " +
                           count(walls) + "; --wall-ratio sets h/D");
  if (moduli > 0)
    options.note(options.youngs_modulus
                     ? "Young's modulus " + format_number(*options.youngs_modulus) + " Pa for " + count(moduli) +
                           " (--youngs-modulus)"
                     : "Young's modulus from hemotree's E(D) table (vgen --print-rules) for " + count(moduli) +
                           "; --youngs-modulus sets one");
}

}  // namespace hemotree
