// Phase separation at diverging bifurcations (Pries & Secomb 2005, constants of Secomb's
// NetFlow) and the Fahraeus effect (Pries, Neuhaus & Gaehtgens 1992). See the header and
// docs/physics.md.
#include "physics/phase_separation.hpp"

#include <cmath>
#include <cstddef>
#include <sstream>
#include <string_view>

#include "core/errors.hpp"

namespace hemotree {

namespace {

constexpr double metres_to_micrometres = 1e6;

// NetFlow's RheolParams.dat, "bifpar": X0, B and A coefficients of the law.
constexpr double threshold_coefficient = 0.964;
constexpr double steepness_coefficient = 6.98;
constexpr double asymmetry_coefficient = -13.29;

[[noreturn]] void refuse(std::string_view law, std::string_view what, double value,
                         std::string_view range) {
  std::ostringstream message;
  message << law << ": " << what << " " << value << " is outside " << range;
  throw InputError(message.str());
}

// The negated comparisons also refuse NaN.
void require_positive(std::string_view law, std::string_view what, double value) {
  if (!(value > 0) || !std::isfinite(value)) refuse(law, what, value, "(0, inf)");
}

void require_hematocrit(std::string_view law, std::string_view what, double value) {
  if (!(value >= 0 && value < 1)) refuse(law, what, value, "[0, 1)");
}

constexpr std::string_view bifurcation_law = "phase separation law";

void require_bifurcation(const Bifurcation& b) {
  require_positive(bifurcation_law, "feed diameter [m]", b.feed_diameter);
  require_positive(bifurcation_law, "first daughter diameter [m]", b.first_diameter);
  require_positive(bifurcation_law, "second daughter diameter [m]", b.second_diameter);
  require_positive(bifurcation_law, "diameter scale", b.diameter_scale);
  require_hematocrit(bifurcation_law, "feed discharge hematocrit", b.feed_hematocrit);
  if (!(b.flow_fraction >= 0 && b.flow_fraction <= 1))
    refuse(bifurcation_law, "flow fraction into the first daughter", b.flow_fraction, "[0, 1]");
}

double logit(double x) { return std::log(x / (1 - x)); }

}  // namespace

PhaseSeparationLaw phase_separation_law(const Bifurcation& bifurcation) {
  require_bifurcation(bifurcation);
  const double feed_um =
      bifurcation.feed_diameter * bifurcation.diameter_scale * metres_to_micrometres;
  // (1 - H_F) / D_F: the plasma-rich wall layer against the feed's width; every
  // parameter of the law grows with it, so separation is strong in narrow, dilute feeds.
  const double layer = (1 - bifurcation.feed_hematocrit) / feed_um;
  const double ratio = std::pow(bifurcation.first_diameter / bifurcation.second_diameter, 2);

  PhaseSeparationLaw law;
  law.x0 = threshold_coefficient * layer;
  law.a = asymmetry_coefficient * (ratio - 1) / (ratio + 1) * layer;
  law.b = 1 + steepness_coefficient * layer;
  if (!(law.x0 < 0.5)) {
    std::ostringstream message;
    message << bifurcation_law << ": feed diameter " << bifurcation.feed_diameter
            << " m (scaled " << feed_um << " um) at discharge hematocrit "
            << bifurcation.feed_hematocrit << " gives a plasma-skimming threshold X0 = " << law.x0
            << ", outside [0, 0.5): the scaled feed diameter must exceed "
            << 2 * threshold_coefficient * (1 - bifurcation.feed_hematocrit) << " um";
    throw InputError(message.str());
  }
  return law;
}

bool law_splits(const Bifurcation& b) {
  const double feed_um = b.feed_diameter * b.diameter_scale * metres_to_micrometres;
  return threshold_coefficient * (1 - b.feed_hematocrit) / feed_um < 0.5;
}

double red_cell_fraction(const Bifurcation& bifurcation) {
  const PhaseSeparationLaw law = phase_separation_law(bifurcation);
  const double fqb = bifurcation.flow_fraction;
  // A daughter drawing no more than the fraction X0 of the flow skims only the
  // cell-free layer near the wall: plasma alone.
  if (fqb <= law.x0) return 0;
  if (fqb >= 1 - law.x0) return 1;
  const double shifted = (fqb - law.x0) / (1 - 2 * law.x0);  // in (0, 1) here
  // 1 / (1 + e^-z) with z the logit of FQE; for large |z| it saturates at 0 or 1 cleanly.
  return 1 / (1 + std::exp(-(law.a + law.b * logit(shifted))));
}

DaughterHematocrits daughter_hematocrits(const Bifurcation& bifurcation) {
  const double fqe = red_cell_fraction(bifurcation);
  const double fqb = bifurcation.flow_fraction;
  const double feed = bifurcation.feed_hematocrit;
  // Red-cell flux into a daughter over its blood flux; FQE = 0 wherever FQB = 0 (and
  // FQE = 1 wherever FQB = 1), so a daughter without flow gets the skimming limit 0.
  DaughterHematocrits daughters;
  daughters.first = fqb > 0 ? fqe * feed / fqb : 0;
  daughters.second = fqb < 1 ? (1 - fqe) * feed / (1 - fqb) : 0;
  return daughters;
}

double mixed_hematocrit(std::span<const double> inflows, std::span<const double> hematocrits) {
  constexpr std::string_view law = "hematocrit mixing";
  if (inflows.size() != hematocrits.size()) {
    std::ostringstream message;
    message << law << ": " << inflows.size() << " inflows but " << hematocrits.size()
            << " hematocrits";
    throw InputError(message.str());
  }
  double blood = 0;
  double cells = 0;
  for (std::size_t i = 0; i < inflows.size(); ++i) {
    if (!(inflows[i] >= 0) || !std::isfinite(inflows[i]))
      refuse(law, "inflow [m^3/s]", inflows[i], "[0, inf)");
    require_hematocrit(law, "inflow discharge hematocrit", hematocrits[i]);
    blood += inflows[i];
    cells += inflows[i] * hematocrits[i];
  }
  // No blood in, none out: the outflows' hematocrit carries no red cells whatever it is.
  return blood > 0 ? cells / blood : 0;
}

double fahraeus_parameter(double diameter, double diameter_scale) {
  constexpr std::string_view law = "Fahraeus law";
  require_positive(law, "diameter [m]", diameter);
  require_positive(law, "diameter scale", diameter_scale);
  const double d = diameter * diameter_scale * metres_to_micrometres;
  // The ratio of the red cells' mean velocity to the blood's, inverted, in the dilute limit:
  // cells crowd the fast core, so they spend less time in the tube than the plasma and fill
  // less of it.
  return 1 + 1.7 * std::exp(-0.415 * d) - 0.6 * std::exp(-0.011 * d);
}

double tube_hematocrit(double discharge_hematocrit, double diameter, double diameter_scale) {
  require_hematocrit("Fahraeus law", "discharge hematocrit", discharge_hematocrit);
  const double x = fahraeus_parameter(diameter, diameter_scale);
  const double h = discharge_hematocrit;
  return h * (h + (1 - h) * x);
}

}  // namespace hemotree
