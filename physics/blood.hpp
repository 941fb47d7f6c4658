// Blood as the laws see it: density, plasma viscosity, discharge hematocrit, the velocity
// profile's coefficient, the rheology law and the red cells' size, with the scalings that
// carry the Pries laws (fitted to human and rat cells) to another species. SI units.
#pragma once

#include <limits>
#include <optional>
#include <string_view>

namespace hemotree {

enum class Rheology { pries, newtonian };

struct Blood {
  double density = 1050.0;            // [kg/m^3]
  double plasma_viscosity = 1.0e-3;   // [Pa s], water (the paper's nu = 1e-6 m^2/s)
  double hematocrit = 0.45;           // discharge hematocrit H_d
  double alpha = 4.0 / 3.0;           // velocity-profile (Coriolis) coefficient; 4/3 parabolic
  // The coefficient of the momentum flux alpha Q^2 / A alone, where a model takes it apart from
  // the profile that sets the friction and the wall shear stress (openBF: 1 in the flux, its
  // friction 8 pi mu); NaN: alpha, as the profile says.
  double momentum_flux_coefficient = std::numeric_limits<double>::quiet_NaN();
  Rheology rheology = Rheology::pries;
  double newtonian_viscosity = 3.4e-3;   // [Pa s], the paper's constant-viscosity runs
  double pries_max_diameter = 300e-6;    // [m]; above it the viscosity stays at its value there
  // Mean red-cell volume [m^3]: the Pries laws were fitted to human blood (92 fl); for
  // another species the diameters entering them scale by (92 fl / MCV)^(1/3), as in Secomb's
  // NetFlow (rat: 55 fl).
  double mean_cell_volume = human_mean_cell_volume;
  static constexpr double human_mean_cell_volume = 92e-18;

  // The momentum flux's coefficient: momentum_flux_coefficient where given, else alpha.
  double momentum_alpha() const { return momentum_flux_coefficient == momentum_flux_coefficient ? momentum_flux_coefficient : alpha; }
  // The factor on a diameter before it enters the Pries laws.
  double pries_diameter_scale() const;
  // The same for the Pries-Secomb phase separation law, whose constants were fitted to
  // networks of the rat mesentery (Pries et al. 1989, Pries & Secomb 2005), cells of about
  // 55 fl: (55 fl / MCV)^(1/3), 1 for rat blood (NetFlow's dishem.cpp, which does not scale)
  // and 0.84 for human blood (larger cells see a narrower vessel).
  double phase_separation_diameter_scale() const;
  static constexpr double phase_separation_mean_cell_volume = 55e-18;
};

// The law's name: "pries" or "newtonian" (the network format's and the reports' word), and
// the law of a name (none for any other word).
std::string_view to_string(Rheology rheology);
std::optional<Rheology> rheology_of(std::string_view name);

}  // namespace hemotree
