// A tapered vessel (Network::distal_diameter): the tube law along it and the source term its
// taper adds. The 1D model of one vessel in conservative form, U = (A, Q):
//   dA/dt + dQ/dx = 0
//   dQ/dt + d/dx(alpha Q^2/A + beta A^(3/2) / (3 rho)) = -k mu Q / (rho A),  k = 2 pi alpha/(alpha - 1)
// with the tube law p = p_ref + beta (sqrt(A) - sqrt(A_ref)) (physics/tube_law.hpp; k:
// physics/poiseuille.hpp). Where beta and A_ref are constant along the vessel, (A/rho) dp/dx is
// the x-derivative of beta A^(3/2)/(3 rho); a tapered vessel's vary, and what the flux then
// misses is a source term (VesselTaper::source_coefficients). It is the paper's system (eq.
// govEq) with Q = A u: smooth solutions are the same, and in (A, Q) the system is a
// conservation law for any alpha, so mass is conserved exactly at every interface.
#pragma once

#include <cmath>
#include <numbers>

#include "physics/tube_law.hpp"
#include "physics/wall_law.hpp"

namespace hemotree {

// A tapered vessel (Network::distal_diameter): its reference lumen diameter D(s) is linear in
// the fraction s in [0, 1] from `from`, and so is its radius (openBF's Rp, Rd). The wall keeps
// its thickness h and modulus E along it, as in openBF, so beta follows the local radius
// (beta ~ E h / R^2 for a thin wall); a beta given directly (net.beta) is the proximal one, and
// scales the same way, beta(s) = beta(0) (D(0) / D(s))^2, with p_ref constant. The wall model
// (thin or thick) is the one of the proximal diameter for the whole vessel: a switch inside
// it would put a jump of beta there. Either way the measured lumen pi D(s)^2 / 4 is at one
// pressure all along (p_ext for a wall, p_ref for a given beta): the rest state.
struct VesselTaper {
  double d0 = 0, d1 = 0;  // reference lumen diameters at from and to [m]
  double length = 0;
  double density = 0, alpha = 4.0 / 3.0;
  bool given_beta = false;
  double beta0 = 0, reference_pressure = 0;  // a given beta at d0, and its p_ref
  WallProperties wall;                       // otherwise the wall (diameter unused) and its model
  WallModel model = WallModel::thin;
  double external_pressure = 0;

  double diameter(double s) const { return d0 + (d1 - d0) * s; }
  // The tube law at fraction s.
  TubeLaw at(double s) const {
    const double d = diameter(s);
    TubeLaw law;
    if (given_beta) {
      law.beta = beta0 * (d0 / d) * (d0 / d);
      law.reference_area = std::numbers::pi / 4 * d * d;
      law.reference_pressure = reference_pressure;
    } else {
      const WallProperties w{d, wall.wall_thickness, wall.youngs_modulus};
      law = model == WallModel::thin ? thin_wall_tube_law(w, external_pressure) : thick_wall_tube_law(w, external_pressure);
    }
    law.density = density;
    law.alpha = alpha;
    return law;
  }
  // The lumen at rest, where the pressure is the same all along.
  double rest_area(double s) const { return std::numbers::pi / 4 * diameter(s) * diameter(s); }

  // The momentum equation's taper terms at fraction s. With p = beta(x) sqrt(A) + c(x),
  // c = p_ref - beta sqrt(A_ref), the pressure force (A/rho) dp/dx is the x-derivative of the
  // flux's beta A^(3/2) / (3 rho) plus (A/rho) ((2/3) beta' sqrt(A) + c') (docs/solver.md §1a),
  // which moves to the right-hand side: S = A (g1 sqrt(A) + g0), g1 = -(2/3) beta' / rho,
  // g0 = -c' / rho. The x-derivatives are fourth-order central differences of the law (the
  // thick wall has no handy closed form); what they miss, like the quadrature's error, is
  // removed at rest by the solver's rest-state correction.
  void source_coefficients(double s, double& g1, double& g0) const {
    constexpr double ds = 1e-3;
    auto parts = [&](double at, double& beta, double& c) {
      const TubeLaw law = this->at(at);
      beta = law.beta;
      c = law.pressure_of_root(0, std::sqrt(law.reference_area));  // p where sqrt(A) = 0
    };
    double b[4], c[4];
    const double offsets[4] = {-2, -1, 1, 2};
    for (int i = 0; i < 4; ++i) parts(s + offsets[i] * ds, b[i], c[i]);
    const double scale = 1 / (12 * ds * length);  // d/dx = (1/L) d/ds
    const double beta_x = (b[0] - 8 * b[1] + 8 * b[2] - b[3]) * scale;
    const double c_x = (c[0] - 8 * c[1] + 8 * c[2] - c[3]) * scale;
    g1 = -2.0 / 3.0 * beta_x / density;
    g0 = -c_x / density;
  }
};

}  // namespace hemotree
