// The tapered 0D vessels (pulse/lumped_vessels.hpp): a vessel whose lumen narrows along it
// holds int A(p, x) dx, its resistance int k mu(A) / A^2 dx along the rigid taper's pressure
// profile, its inertance rho int dx / A (docs/solver.md §10), each by an eight-point rule.
#include <cmath>
#include <numbers>

#include "physics/poiseuille.hpp"
#include "pulse/lumped_vessels.hpp"

namespace hemotree {

LumpedVessels::TaperedEdge LumpedVessels::describe_taper(const VesselTaper& taper, double alpha) {
  // sqrt(A) = c(x) + d(x) p with c = sqrt(A_ref) - p_ref / beta, d = 1 / beta, so
  // int A dx = p^2 int d^2 dx + 2 p int c d dx + int c^2 dx: eight Gauss points along it.
  TaperedEdge t;
  t.taper = taper;
  auto root = [&](double x, double& c, double& d) {
    const TubeLaw law = taper.at(x);
    d = law.lumen_root_slope();
    c = law.lumen_root_intercept();
  };
  for (std::size_t i = 0; i < taper_rule_nodes.size(); ++i) {
    double c, d;
    root(taper_rule_nodes[i], c, d);
    const double w = taper_rule_weights[i] * taper.length;
    t.volume_a += w * d * d;
    t.volume_b += 2 * w * c * d;
    t.volume_c += w * c * c;
    // The rule's points in u, the fraction of the rigid taper's resistance, where its
    // pressure profile puts p = pa - (pa - pb) u.
    const double diameter = tapered_resistance_diameter(taper.d0, taper.d1, taper_rule_nodes[i]);
    const double x = taper.d1 != taper.d0 ? (diameter - taper.d0) / (taper.d1 - taper.d0) : taper_rule_nodes[i];
    root(x, t.root_c[i], t.root_d[i]);
    t.rigid_area[i] = std::numbers::pi / 4 * diameter * diameter;
  }
  t.unit_resistance = tapered_poiseuille_resistance(1.0, taper.length, taper.d0, taper.d1, alpha);
  return t;
}

double LumpedVessels::tapered_resistance(std::int32_t index, double pa, double pb) const {
  // R = int k mu(A) / A^2 dx = R_1 int_0^1 mu(A) (A_rigid / A)^2 du (physics/poiseuille.hpp's
  // substitution), A at the rigid taper's pressure p(u) = pa - (pa - pb) u: exact for a rigid
  // taper, and it follows the distension along the vessel as the uniform vessels' Simpson rule does.
  const TaperedEdge& t = tapered_[static_cast<std::size_t>(taper_edge_[static_cast<std::size_t>(index)])];
  double sum = 0;
  for (std::size_t i = 0; i < taper_rule_nodes.size(); ++i) {
    const double root = t.root_c[i] + t.root_d[i] * (pa - (pa - pb) * taper_rule_nodes[i]);
    const double area = root * root, ratio = t.rigid_area[i] / area;
    sum += taper_rule_weights[i] * (*viscosity_)(area) * ratio * ratio;
  }
  return t.unit_resistance * sum;
}

double LumpedVessels::tapered_inertance(std::int32_t index, double pa, double pb) const {
  // rho int dx / A with the lumen at the mean pressure, as a uniform vessel's: on the
  // resistance's points u, dx = (R_1 / k) A_rigid^2 du, so int dx / A = (R_1 / k) int
  // A_rigid^2 / A du, a smooth integrand (about A_rigid).
  const TaperedEdge& t = tapered_[static_cast<std::size_t>(taper_edge_[static_cast<std::size_t>(index)])];
  const double p = 0.5 * (pa + pb);
  double sum = 0;
  for (std::size_t i = 0; i < taper_rule_nodes.size(); ++i) {
    const double root = t.root_c[i] + t.root_d[i] * p;
    sum += taper_rule_weights[i] * t.rigid_area[i] * t.rigid_area[i] / (root * root);
  }
  return density_ * t.unit_resistance / friction_k_ * sum;
}

double LumpedVessels::tapered_compliance(std::int32_t index, double p) const {
  const TaperedEdge& t = tapered_[static_cast<std::size_t>(taper_edge_[static_cast<std::size_t>(index)])];
  return 2 * t.volume_a * p + t.volume_b;
}

double LumpedVessels::tapered_volume(std::int32_t index) const {
  const auto e = static_cast<std::size_t>(index);
  const TaperedEdge& t = tapered_[static_cast<std::size_t>(taper_edge_[e])];
  double v = 0;
  for (const std::int32_t k : {a_[e], b_[e]}) {
    const double p = pressure_[static_cast<std::size_t>(k)];
    v += 0.5 * ((t.volume_a * p + t.volume_b) * p + t.volume_c);
  }
  return v;
}

double LumpedVessels::resistance_fraction(std::size_t e, double x) const {
  const VesselTaper& taper = tapered_[static_cast<std::size_t>(taper_edge_[e])].taper;
  if (taper.d1 == taper.d0) return x;
  const double d = taper.diameter(x);
  const double inverse_cube0 = 1 / (taper.d0 * taper.d0 * taper.d0), inverse_cube1 = 1 / (taper.d1 * taper.d1 * taper.d1);
  return (inverse_cube0 - 1 / (d * d * d)) / (inverse_cube0 - inverse_cube1);
}

}  // namespace hemotree
