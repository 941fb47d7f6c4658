// The tube law of a vessel: its wall's answer p(A) to the lumen A, and all that the 1D, 0D
// and steady models take from it. The one law today is the elastic sqrt(A) law
//   p(A) = p_ref + beta (sqrt(A) - sqrt(A_ref))
// (Olufsen 1999; Formaggia, Lamponi and Quarteroni 2003; openBF; Nektar++'s
// PulseWaveSystem "Beta" law), with beta and p_ref from the thin- or thick-walled models of
// Causin et al. as the source paper gives them (physics/wall_law.hpp) or given per vessel.
// What follows from it, with rho the blood's density and alpha its momentum-flux factor:
//   A(p)       = (sqrt(A_ref) + (p - p_ref) / beta)^2           the inverse (0 where the root is)
//   dA/dp      = 2 sqrt(A) / beta                               compliance per length
//   dp/dA      = beta / (2 sqrt(A))                             its inverse
//   c^2        = (A / rho) dp/dA = beta sqrt(A) / (2 rho)       wave speed (Moens-Korteweg)
//   F(A, Q)    = (Q, alpha Q^2 / A + beta A^(3/2) / (3 rho))    the 1D flux in U = (A, Q)
//   lambda+-   = alpha u +- sqrt(c^2 + alpha (alpha - 1) u^2)   characteristic speeds, u = Q / A
//   P          = p(A) + rho u^2 / 2                             total pressure
// (beta A^(3/2) / (3 rho) is int_0^A (a / rho) dp/da da: the pressure force in conservation
// form, exact where beta is constant along the vessel; a taper's remainder is a source term,
// physics/vessel_taper.hpp). The law is linear in sqrt(A), and two forms use that: Newton
// iterations at the vessel ends take sqrt(A) once per step (pressure_of_root), and the 0D
// vessels hold sqrt(A) = c + d p, linear in p, so a vessel's volume is a quadratic in p.
//
// A new wall law (viscoelastic, a nonlinear fit) is a new file modelled on this one: a value
// type that satisfies TubeLawInterface below, and the factory that builds it from a vessel's
// data. The DG operator, the Riemann problems and the steady distension use only what the
// concept states; the 0D vessels' quadratic volume and the junction's root form are this
// law's own (docs/physics.md says where they go for another).
#pragma once

#include <cmath>
#include <concepts>

namespace hemotree {

// What every wall law gives, in SI units; a the lumen [m^2], q the flow [m^3/s], p [Pa].
template <class Law>
concept TubeLawInterface = std::copyable<Law> && requires(const Law law, double a, double q, double p, double length) {
  { law.pressure(a) } -> std::same_as<double>;               // p(A)
  { law.area(p) } -> std::same_as<double>;                   // A(p), its inverse
  { law.compliance_per_length(a) } -> std::same_as<double>;  // dA/dp
  { law.pressure_slope(a) } -> std::same_as<double>;         // dp/dA
  { law.compliance(length, a) } -> std::same_as<double>;     // L dA/dp, a 0D vessel's
  { law.wave_speed(a) } -> std::same_as<double>;             // c = sqrt(A/rho dp/dA)
  { law.flux_area(a, q) } -> std::same_as<double>;           // F_A
  { law.flux_flow(a, q) } -> std::same_as<double>;           // F_Q
  { law.lambda_forward(a, q) } -> std::same_as<double>;      // lambda+
  { law.lambda_backward(a, q) } -> std::same_as<double>;     // lambda-
  { law.total_pressure(a, q) } -> std::same_as<double>;      // p + rho u^2 / 2
};

// The sqrt(A) law of one vessel (a tapered one's at one point: VesselTaper::at), with the two
// numbers of the blood that its flux and wave speed need. Each expression keeps the order of
// operations the solvers had when they wrote it out, so their results are the same bits.
struct TubeLaw {
  double beta = 0;                // [Pa/m]
  double reference_area = 0;      // A_ref [m^2]
  double reference_pressure = 0;  // p_ref [Pa]
  double density = 0;             // rho [kg/m^3]: the wave speed and the fluxes need it
  double alpha = 4.0 / 3.0;       // momentum-flux factor of the velocity profile (4/3: Poiseuille)

  // --- the law in r = sqrt(A), where it is linear: p = p_ref + beta (r - r_ref) ------------
  // For Newton iterations that hold r and r_ref = sqrt(A_ref) already: one root per step.
  double pressure_of_root(double root, double reference_root) const {
    return reference_pressure + beta * (root - reference_root);
  }
  double pressure_slope_of_root(double root) const { return beta / (2 * root); }  // dp/dA
  // sqrt(A(p)): negative below the collapse pressure p_ref - beta sqrt(A_ref).
  double lumen_root(double p) const { return std::sqrt(reference_area) + (p - reference_pressure) / beta; }
  // The same as c + d p, linear in p (the 0D vessels' form): d = 1 / beta, c = sqrt(A_ref) - p_ref / beta.
  double lumen_root_slope() const { return 1 / beta; }
  double lumen_root_intercept() const { return std::sqrt(reference_area) - reference_pressure / beta; }

  // --- p(A), A(p) and their derivatives -----------------------------------------------------
  double pressure(double a) const { return pressure_of_root(std::sqrt(a), std::sqrt(reference_area)); }
  // The exact inverse on p >= p_ref - beta sqrt(A_ref), where the law reaches sqrt(A) = 0.
  // Below it the law has no root; the lumen is taken as collapsed (A = 0, the continuous
  // extension) rather than the square of a negative root, a spurious re-opened lumen.
  double area(double p) const {
    const double root = lumen_root(p);
    return root > 0 ? root * root : 0.0;
  }
  double pressure_slope(double a) const { return pressure_slope_of_root(std::sqrt(a)); }
  double compliance_per_length(double a) const { return 2 * std::sqrt(a) / beta; }
  // A vessel of length L held at one lumen A: C = L dA/dp [m^3/Pa].
  double compliance(double length, double a) const { return length * 2 * std::sqrt(a) / beta; }
  double wave_speed(double a) const { return std::sqrt(beta * std::sqrt(a) / (2 * density)); }

  // --- the 1D equations ---------------------------------------------------------------------
  double flux_area(double, double q) const { return q; }
  double flux_flow(double a, double q) const { return alpha * q * q / a + beta * a * std::sqrt(a) / (3 * density); }
  // The pressure part of F_Q, beta A^(3/2) / (3 rho), given beta / (3 rho), for a double or an
  // Eigen array of points (the DG volume term evaluates it for a block of elements at once,
  // each row with its own beta, in this order: (beta / (3 rho)) A sqrt(A)).
  template <class Coefficient, class Area>
  static auto pressure_flux(const Coefficient& beta_over_3rho, const Area& a) {
    using std::sqrt;
    return beta_over_3rho * a * sqrt(a);
  }
  double lambda_forward(double a, double q) const {
    const double u = q / a, c = wave_speed(a);
    return alpha * u + std::sqrt(c * c + alpha * (alpha - 1) * u * u);
  }
  double lambda_backward(double a, double q) const {
    const double u = q / a, c = wave_speed(a);
    return alpha * u - std::sqrt(c * c + alpha * (alpha - 1) * u * u);
  }
  double total_pressure(double a, double q) const {
    const double u = q / a;
    return pressure(a) + 0.5 * density * u * u;
  }
};

static_assert(TubeLawInterface<TubeLaw>);

}  // namespace hemotree
