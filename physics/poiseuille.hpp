// Steady viscous resistance of a vessel with the velocity profile of the 1D model.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace hemotree {

// The friction coefficient k = 2 pi alpha/(alpha - 1) of the velocity profile whose
// momentum-flux factor is alpha: the 1D friction is -k mu Q / A per unit length (8 pi mu u for
// the parabolic profile, alpha = 4/3), and the steady resistance k mu l / A^2 below.
inline double friction_coefficient(double alpha) { return 2 * std::numbers::pi * alpha / (alpha - 1); }

// Friction f = -2 pi mu alpha/(alpha - 1) u per unit length gives, in steady flow,
// dp/dx = -2 pi mu alpha/(alpha - 1) Q / A^2, so R = 2 pi mu alpha/(alpha - 1) l / A^2;
// alpha = 4/3 (Poiseuille) gives R = 128 mu l / (pi D^4). (k mu l / A^2 written out, in the
// order of operations whose bits the steady runs and vprune's outlets were recorded with.)
inline double poiseuille_resistance(double viscosity, double length, double diameter,
                                    double alpha) {
  const double area = std::numbers::pi / 4 * diameter * diameter;
  return 2 * std::numbers::pi * viscosity * alpha / (alpha - 1) * length / (area * area);
}

// A compliant tube's flow capacity G = A^2 / (k mu) [m^4/(Pa s)]:
// its steady flow is (1/l) int_{p_b}^{p_a} G(p) dp, G at the lumen A(p) and viscosity mu(A).
inline double flow_capacity(double area, double viscosity, double k_friction) { return area * area / (k_friction * viscosity); }

// The pressure at fraction x of a compliant tube's steady profile between end pressures pa
// and pb where its flow capacity is ga and gb (G linear in p between them): with
// int_p^pa G dp = x int_pb^pa G dp a quadratic in d = pa - p, G_a d - g d^2 / 2 = x F,
// g = (G_a - G_b) / (pa - pb). What a 0D vessel reports inside it (pulse/lumped_vessels.hpp)
// and --linear at a vessel's middle.
inline double steady_profile_pressure(double pa, double pb, double ga, double gb, double x) {
  const double drop = pa - pb;
  if (drop == 0) return pa;
  const double slope = (ga - gb) / drop, f = x * drop * 0.5 * (ga + gb);
  const double disc = ga * ga - 2 * slope * f;
  return pa - 2 * f / (ga + std::sqrt(std::max(disc, 0.0)));
}

// A tapered vessel, its lumen diameter linear from d0 (at `from`) to d1 (at `to`), with a
// constant viscosity: R = k mu int_0^L dx / A(x)^2, k = 2 pi alpha/(alpha - 1), A = pi D^2/4, and
//   int_0^L dx / D(x)^4 = L (d0^2 + d0 d1 + d1^2) / (3 d0^3 d1^3)
// (D' = (d1 - d0)/L: the integral is (1/D0^3 - 1/D1^3) / (3 D') = L (D1^3 - D0^3) / (3 D0^3 D1^3 (D1 - D0))).
// d0 = d1 gives poiseuille_resistance.
inline double tapered_poiseuille_resistance(double viscosity, double length, double d0, double d1, double alpha) {
  constexpr double pi = std::numbers::pi;
  const double k = friction_coefficient(alpha);
  return k * viscosity * 16 / (pi * pi) * length * (d0 * d0 + d0 * d1 + d1 * d1) / (3 * d0 * d0 * d0 * d1 * d1 * d1);
}

// Where a tapered rigid vessel has built the fraction u of its resistance (at constant
// viscosity): the diameter there, from int_0^x dx/D^4 = u int_0^L dx/D^4, i.e. 1/D^3 linear
// in u. The substitution x -> u takes the 1/D^4 weight out of an integral along the vessel.
inline double tapered_resistance_diameter(double d0, double d1, double u) {
  return 1 / std::cbrt((1 - u) / (d0 * d0 * d0) + u / (d1 * d1 * d1));
}

// Eight-point Gauss-Legendre rule on [0, 1] (nodes, weights): exact for polynomials of
// degree 15, used along tapered vessels.
inline constexpr std::array<double, 8> taper_rule_nodes = {
    0.0198550717512318842, 0.1016667612931866302, 0.2372337950418355070, 0.4082826787521750976,
    0.5917173212478249024, 0.7627662049581644930, 0.8983332387068133698, 0.9801449282487681158};
inline constexpr std::array<double, 8> taper_rule_weights = {
    0.0506142681451881296, 0.1111905172266872352, 0.1568533229389436437, 0.1813418916891809915,
    0.1813418916891809915, 0.1568533229389436437, 0.1111905172266872352, 0.0506142681451881296};

// The same with a viscosity that depends on the diameter (Pries): R = k int mu(D(x)) / A^2 dx
// = R_1 int_0^1 mu(D(u)) du, R_1 the resistance at unit viscosity and D(u) as above. The
// integrand is smooth in u (mu varies slowly with D), so eight Gauss points integrate it to
// far below the law's own accuracy, however strong the taper; at constant viscosity it is the
// closed form.
template <class ViscosityOfDiameter>
double tapered_poiseuille_resistance(const ViscosityOfDiameter& viscosity, double length, double d0, double d1,
                                     double alpha) {
  double mean = 0;
  for (std::size_t i = 0; i < taper_rule_nodes.size(); ++i)
    mean += taper_rule_weights[i] * viscosity(tapered_resistance_diameter(d0, d1, taper_rule_nodes[i]));
  return tapered_poiseuille_resistance(mean, length, d0, d1, alpha);
}

// Inertance of a vessel, rho int_0^L dx / A(x) [Pa s^2/m^3]: with D linear from d0 to d1,
// int dx / D^2 = L / (d0 d1), so L_q = 4 rho L / (pi d0 d1) (rho L / A when uniform).
inline double tapered_inertance(double density, double length, double d0, double d1) {
  return 4 * density * length / (std::numbers::pi * d0 * d1);
}

}  // namespace hemotree
