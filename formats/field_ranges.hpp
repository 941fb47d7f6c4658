// The accepted range of every number a network file carries (docs/network-format.md,
// "Accepted ranges"). The reader refuses anything outside them, so that every stage can
// trust that what it computes from a network is finite: each bound is far beyond any
// physiological or experimental value (checked against vgen's full tree, the Boileau 2015
// cases, ADAN56 and the other openBF models, the rat mesentery) and far inside the values
// at which the physics overflows, underflows or leaves its laws' domains.
// Tools that build the same quantities from flags (vprune's blood and inflow) can check
// them against the same ranges, so that what they write the reader reads back.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace hemotree {

struct FieldRange {
  double min, max;        // closed interval
  std::string_view unit;  // SI, "" when dimensionless
  bool contains(double v) const { return v >= min && v <= max; }  // false for NaN
};

// "[1e-7, 10] m"
std::string describe(const FieldRange& range);
// Shortest text that reads back as the same double, with a plain exponent ("1e-320").
std::string format_number(double value);
// "\"length\" must lie in [1e-7, 10] m (got 1e-320)"
std::string out_of_range(std::string_view field, const FieldRange& range, double got);

namespace ranges {

// --- vessels -------------------------------------------------------------------------------
// 0.1 um is below any segment a network can resolve (a red cell is 8 um long); 10 m is
// beyond any vessel of any animal. The shortest length sets the solver's step, so this also
// keeps the number of steps finite.
inline constexpr FieldRange length{1e-7, 10, "m"};
// The Pries viscosity law is singular at 1.1 um and meaningless below a red cell's passage
// (the narrowest measured capillaries are about 3 um; vgen stops near 5 um); 0.5 m is twice
// a blue whale's aorta.
inline constexpr FieldRange diameter{2e-6, 0.5, "m"};
// 10 nm is thinner than any endothelium (0.2-0.5 um in capillaries); 0.1 m is far thicker
// than any arterial wall (a few mm). Together with the diameters this keeps the thick-wall
// law's areas and the wave speeds finite.
inline constexpr FieldRange wall_thickness{1e-8, 0.1, "m"};
// 1 kPa is softer than any vessel wall (brain tissue); 10 GPa is stiffer than rigid plastic
// tubing of in vitro models. Real values: 0.16-0.63 MPa (vgen), 0.2-1.6 MPa (ADAN56).
inline constexpr FieldRange youngs_modulus{1e3, 1e10, "Pa"};
// beta = (4/3) sqrt(pi) E h / A over the ranges above spans about 1e-4 .. 1e21 Pa/m.
inline constexpr FieldRange beta{1e-4, 1e21, "Pa/m"};
// Pressures, here and for the outlets: +-1e5 Pa (750 mmHg) holds every physiological
// pressure (0-300 mmHg) and any external or venous offset.
inline constexpr FieldRange pressure{-1e5, 1e5, "Pa"};
// Generations are rows of per-generation tables: a root is 0 and no vessel of a tree lies
// deeper than the vessel count - 1; the upper bound is checked against the count once all
// vessels are read. This one, the storage's, is checked as each value is read.
inline constexpr std::int64_t max_generation = 2'147'483'646;
// Node coordinates only place the drawing: anything within a kilometre.
inline constexpr FieldRange coordinate{-1e3, 1e3, "m"};

// --- outlets (0D models) -------------------------------------------------------------------
// 1 Pa s/m^3 is far below a whole body's peripheral resistance (~1e8); 1e24 lies beyond the
// Poiseuille resistance of the narrowest, longest vessel above (2.5e24 needs 2 um over 10 m
// at 0.1 Pa s); R1 and R2 of an RCR may each be 0 but not both.
inline constexpr FieldRange resistance{1, 1e24, "Pa s/m^3"};
inline constexpr FieldRange rcr_part{0, 1e24, "Pa s/m^3"};
// Compliances: ADAN56 has 1e-13 .. 4e-9 m^3/Pa, a microvascular outlet much less; 1e-3 m^3/Pa
// (a litre per pascal) is beyond any.
inline constexpr FieldRange compliance{0, 1e-3, "m^3/Pa"};
inline constexpr FieldRange reflection{-1, 1, ""};

// --- blood ---------------------------------------------------------------------------------
// Blood is 1040-1060 kg/m^3, water-glycerol analogues up to about 1260.
inline constexpr FieldRange density{500, 2000, "kg/m^3"};
// Plasma 1.1-1.3 mPa s, water 0.65-1.8 mPa s (40-0 C), analogue fluids a few mPa s, glycerol
// near 1 Pa s only undiluted.
inline constexpr FieldRange viscosity{1e-4, 0.1, "Pa s"};
// Physiological discharge hematocrits stay below 0.7 (polycythemia); at 1 the Pries law's
// hematocrit factor diverges.
inline constexpr FieldRange hematocrit{0, 0.9, ""};
// alpha = (n + 2) / (n + 1) for a profile u ~ 1 - (r/R)^n: 2 for n = 0, 4/3 parabolic,
// 1.1 for n = 9; the friction ~ alpha / (alpha - 1) diverges at 1 (a flat profile).
inline constexpr FieldRange alpha{1.001, 2, ""};
// The flux's coefficient alone has no friction to diverge: a flat profile's 1 is its floor.
inline constexpr FieldRange momentum_flux_coefficient{1, 2, ""};
inline constexpr FieldRange pries_max_diameter{2e-6, 0.5, "m"};  // as the diameters
// Mammalian red cells: about 20 fl (goat) to 120 fl (elephant), human 92, rat 55-60; birds
// up to about 160. Diameters enter the Pries laws times (92 fl / MCV)^(1/3): within this
// range the smallest accepted diameter (2 um) stays above 1.5 um, clear of the laws'
// singularity at 1.1 um.
inline constexpr FieldRange mean_cell_volume{15e-18, 200e-18, "m^3"};

// --- the inlet -----------------------------------------------------------------------------
// Hearts beat from about 1200/min (shrew, 0.05 s) to a few per minute (diving whales);
// the period also bounds the steps per cycle.
inline constexpr FieldRange period{0.01, 100, "s"};
// A half sine of 1 ms is already a step; the peak is mean * pi * period / (2 systole).
inline constexpr FieldRange systole{1e-3, 100, "s"};  // and at most the period
// Mean inflows: a single capillary carries about 1e-14 m^3/s, a resting human 1e-4, a whale
// at most about 2e-2; the mean must be positive (results are relative to it).
inline constexpr FieldRange mean_flow{1e-18, 0.1, "m^3/s"};
// Table samples may flow backwards (diastolic reversal), within the same bound.
inline constexpr FieldRange flow_sample{-0.1, 0.1, "m^3/s"};

}  // namespace ranges

}  // namespace hemotree
