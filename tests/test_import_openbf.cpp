// openBF's YAML models: what each key becomes, the refusals, and the shipped models read,
// written and read back.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include <gtest/gtest.h>

#include "cli/setting_words.hpp"
#include "core/errors.hpp"
#include "core/setting_error.hpp"
#include "exchange/openbf.hpp"
#include "tests/shared_networks.hpp"

using namespace hemotree;
namespace fs = std::filesystem;

namespace {

class OpenbfTest : public ::testing::Test {
 protected:
  void SetUp() override {
    folder_ = fs::temp_directory_path() /
              ("hemotree-openbf-" + std::to_string(::getpid()) + "-" +
               ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(folder_);
  }
  void TearDown() override { fs::remove_all(folder_); }

  std::string file(const std::string& name, const std::string& text) const {
    const fs::path p = folder_ / name;
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }
  std::string path(const std::string& name) const { return (folder_ / name).string(); }

  // The message of the InputError that reading the model throws ("" when none).
  std::string refusal(const std::string& model, OpenbfReading reading = OpenbfReading::code) {
    try {
      read_openbf(model, options_, reading);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }

  ImportOptions options_;
  std::vector<std::string> notes_;
  fs::path folder_;
};

// Three vessels: a tapered root without h0, a branch ending in a three-element Windkessel and
// one in a two-element Windkessel.
const char* const three_vessels = R"(project_name: tee
inlet_file: tee_inlet.dat
write_results: ["P"]
solver:
  Ccfl: 0.9
  cycles: 10
  jump: 100
  convergence_tolerance: 1.0
blood:
  rho: 1060.0
  mu: 0.004
network:
  - label: root
    sn: 1
    tn: 2
    L: 0.1
    E: 400000.0
    Rp: 0.010
    Rd: 0.008
    M: 100
    gamma_profile: 9
  - label: left
    sn: 2
    tn: 3
    L: 0.05
    E: 600000.0
    R0: 0.004
    h0: 0.0006
    gamma_profile: 9
    R1: 1.0e8
    R2: 1.0e9
    Cc: 2.0e-10
    Pout: 500.0
  - label: right
    sn: 2
    tn: 4
    L: 0.05
    E: 800000.0
    R0: 0.003
    gamma_profile: 9
    outlet: wk2
    R1: 2.0e9
    Cc: 1.0e-10
)";

const char* const inlet_table = "0.0 0.0\n0.25 1.0e-4\n0.5 4.0e-5\n1.0 0.0\n";

// Avolio's wall law in the form he published it, radius in cm: h/R = a e^(b R) + c e^(d R),
// a = 0.2802, b = -5.053 cm^-1, c = 0.1324, d = -0.1114 cm^-1.
double avolio_wall_m(double radius_m) {
  const double r_cm = radius_m * 100;
  return radius_m * (0.2802 * std::exp(-5.053 * r_cm) + 0.1324 * std::exp(-0.1114 * r_cm));
}

// openBF's thin-wall tube law as openBF writes it (vessel.jl): its beta = sqrt(pi / A0) h0 E /
// (1 - 1/4), its pressure P = Pext + beta (sqrt(A / A0) - 1); hemotree's beta multiplies
// sqrt(A) - sqrt(A0), so it is openBF's over sqrt(A0).
double openbf_tube_beta(double e, double h, double r) {
  const double a0 = std::numbers::pi * r * r;
  return std::sqrt(std::numbers::pi / a0) * h * e / (1 - 0.25) / std::sqrt(a0);
}

// As openBF's documentation reads the model.
TEST_F(OpenbfTest, ReadsEveryKeyOfAHandWrittenModel) {
  file("tee_inlet.dat", inlet_table);
  options_.note = [this](const std::string& s) { notes_.push_back(in_words(s, vimport_words())); };  // as vimport words them
  const Network net = read_openbf(file("tee.yaml", three_vessels), options_, OpenbfReading::documented);

  ASSERT_EQ(net.vessel_count(), 3u);
  ASSERT_EQ(net.node_count(), 4u);
  EXPECT_EQ(net.node_id, (std::vector<std::int64_t>{1, 2, 3, 4}));
  EXPECT_EQ(net.id, (std::vector<std::int64_t>{1, 2, 3}));
  EXPECT_EQ(net.provenance["labels"], (nlohmann::json{"root", "left", "right"}));
  EXPECT_EQ(net.provenance["format"], "openbf");
  EXPECT_EQ(net.generation, (std::vector<std::int32_t>{0, 1, 1}));
  EXPECT_EQ(net.node_id[net.from[2]], 2);
  EXPECT_EQ(net.node_id[net.to[2]], 4);
  EXPECT_FALSE(net.has_coordinates());

  // The root tapers linearly from Rp to Rd; without h0 its wall is openBF's law at the mean
  // radius, 9 mm: 9 mm (0.2802 e^-4.5477 + 0.1324 e^-0.10026) = 1.10463 mm.
  EXPECT_DOUBLE_EQ(net.length[0], 0.1);
  EXPECT_DOUBLE_EQ(net.diameter[0], 0.020);
  ASSERT_TRUE(net.is_tapered(0));
  EXPECT_DOUBLE_EQ(net.distal_diameter[0], 0.016);
  EXPECT_FALSE(net.is_tapered(1));
  EXPECT_NEAR(net.wall_thickness[0], avolio_wall_m(0.009), 1e-15);
  EXPECT_NEAR(net.wall_thickness[0], 1.10463e-3, 1e-8);
  EXPECT_DOUBLE_EQ(net.youngs_modulus[0], 4e5);
  EXPECT_DOUBLE_EQ(net.wall_thickness[1], 6e-4);
  EXPECT_DOUBLE_EQ(net.diameter[2], 0.006);

  // Blood: Newtonian, gamma 9 -> alpha = 11/10.
  ASSERT_TRUE(net.blood);
  EXPECT_DOUBLE_EQ(net.blood->density, 1060);
  EXPECT_EQ(net.blood->rheology, Rheology::newtonian);
  EXPECT_DOUBLE_EQ(net.blood->newtonian_viscosity, 0.004);
  EXPECT_DOUBLE_EQ(net.blood->alpha, 1.1);

  // The inlet feeds vessel 1 at node 1; the period is the table's last time, whose row (the
  // next cycle's t = 0) the periodic table drops.
  ASSERT_TRUE(net.inlet);
  EXPECT_EQ(net.inlet->vessel, 1);
  EXPECT_EQ(net.inlet->waveform.shape, Waveform::Shape::table);
  EXPECT_DOUBLE_EQ(net.inlet->waveform.period, 1.0);
  EXPECT_EQ(net.inlet->waveform.time, (std::vector<double>{0.0, 0.25, 0.5}));
  EXPECT_EQ(net.inlet->waveform.value, (std::vector<double>{0.0, 1e-4, 4e-5}));
  // Trapezoids: (0.25 (0 + 1e-4) + 0.25 (1e-4 + 4e-5) + 0.5 (4e-5 + 0)) / 2 = 4e-5 m^3/s.
  EXPECT_NEAR(net.inlet->waveform.mean_value(), 4e-5, 1e-18);

  ASSERT_EQ(net.outlets.size(), 2u);
  const Outlet& wk3 = net.outlets[0];
  EXPECT_EQ(wk3.vessel, 1);
  EXPECT_EQ(wk3.type, BoundaryType::rcr);
  EXPECT_DOUBLE_EQ(wk3.r1, 1e8);
  EXPECT_DOUBLE_EQ(wk3.r2, 1e9);
  EXPECT_DOUBLE_EQ(wk3.c, 2e-10);
  EXPECT_DOUBLE_EQ(wk3.p_out, 500);

  // The two-element Windkessel: R1 is the total; the proximal part is the characteristic
  // impedance Z = rho c0 / A0, with the Moens-Korteweg speed of openBF's thin wall
  // (Poisson ratio 1/2): c0^2 = E h / (2 rho R (1 - nu^2)). Here h = 3 mm (0.2802 e^-1.5159
  // + 0.1324 e^-0.03342) = 0.5687 mm, c0 = 9.77 m/s, Z = 3.66e8 Pa s/m^3.
  const Outlet& wk2 = net.outlets[1];
  const double r = 0.003, h = avolio_wall_m(r), nu = 0.5;
  const double c0 = std::sqrt(8e5 * h / (2 * 1060 * r * (1 - nu * nu)));
  const double z = 1060 * c0 / (std::numbers::pi * r * r);
  EXPECT_NEAR(z, 3.66e8, 0.01e8);
  EXPECT_EQ(wk2.vessel, 2);
  EXPECT_EQ(wk2.type, BoundaryType::rcr);
  EXPECT_NEAR(wk2.r1, z, 1e-9 * z);
  EXPECT_NEAR(wk2.r1 + wk2.r2, 2e9, 1e-6);
  EXPECT_DOUBLE_EQ(wk2.c, 1e-10);
  // The vessel's own wall (no h0) is the same law, at its (untapered) radius.
  EXPECT_NEAR(net.wall_thickness[2], h, 1e-15);

  EXPECT_DOUBLE_EQ(net.provenance["external_pressure"].get<double>(), 0.0);
  // openBF's thin wall, given as beta at Pext, whatever hemosolve's wall options.
  ASSERT_EQ(net.beta.size(), 3u);
  ASSERT_EQ(net.reference_pressure.size(), 3u);
  for (std::size_t v = 0; v < 3; ++v) {
    EXPECT_NEAR(net.beta[v], openbf_tube_beta(net.youngs_modulus[v], net.wall_thickness[v], net.diameter[v] / 2),
                1e-12 * net.beta[v]);
    EXPECT_EQ(net.reference_pressure[v], 0.0);
  }
  bool told_two_element = false, told_ignored = false;
  for (const std::string& n : notes_) {
    told_two_element |= n.find("two-element Windkessel") != std::string::npos;
    told_ignored |= n.find("Ccfl") != std::string::npos && n.find("M") != std::string::npos;
  }
  EXPECT_TRUE(told_two_element);
  EXPECT_TRUE(told_ignored);
}

// By default the model openBF's code computes (vessel.jl of openBF 2.x): a tapered vessel stays
// at Rp (its code moves the radius by (Rd - Rp) dx only), with its law's wall at Rp; a
// two-element Windkessel keeps R1 and gets R2 = R1 - Z beyond it; each difference from the
// documented reading is one note naming --as-documented.
TEST_F(OpenbfTest, ByDefaultBuildsTheModelOpenbfsCodeComputes) {
  file("tee_inlet.dat", inlet_table);
  options_.note = [this](const std::string& s) { notes_.push_back(in_words(s, vimport_words())); };  // as vimport words them
  const Network net = read_openbf(file("tee.yaml", three_vessels), options_);

  EXPECT_FALSE(net.is_tapered(0));
  EXPECT_DOUBLE_EQ(net.diameter[0], 0.020);
  EXPECT_NEAR(net.wall_thickness[0], avolio_wall_m(0.010), 1e-15);
  EXPECT_NEAR(net.beta[0], openbf_tube_beta(4e5, avolio_wall_m(0.010), 0.010), 1e-12 * net.beta[0]);
  EXPECT_DOUBLE_EQ(net.blood->alpha, 1.1);  // gamma_profile (with the underscore) is read
  EXPECT_EQ(net.blood->momentum_flux_coefficient, 1.0);  // openBF's flux: Q^2 / A
  EXPECT_EQ(net.blood->momentum_alpha(), 1.0);

  // R1 = 2e9 stays proximal; R2 = R1 - Z with Z = 3.66e8 as in the documented reading.
  const double r = 0.003, h = avolio_wall_m(r);
  const double z = 1060 * std::sqrt(8e5 * h / (2 * 1060 * r * 0.75)) / (std::numbers::pi * r * r);
  const Outlet& wk2 = net.outlets[1];
  EXPECT_DOUBLE_EQ(wk2.r1, 2e9);
  EXPECT_NEAR(wk2.r2, 2e9 - z, 1e-6);
  EXPECT_NEAR(wk2.r1 + wk2.r2, 4e9 - z, 1e-6);
  const Outlet& wk3 = net.outlets[0];  // R1, R2 and Cc given: the same in both readings
  EXPECT_DOUBLE_EQ(wk3.r1, 1e8);
  EXPECT_DOUBLE_EQ(wk3.r2, 1e9);

  std::size_t named = 0;
  bool told_taper = false, told_split = false, told_alpha = false;
  for (const std::string& n : notes_) {
    named += n.find("--as-documented") != std::string::npos;
    told_taper |= n.rfind("1 tapered vessel (Rp != Rd): uniform at Rp", 0) == 0;
    told_split |= n.find("R2 = R1 - Z beyond it") != std::string::npos;
    told_alpha |= n.rfind("momentum flux: alpha = 1 (blood momentum_flux_coefficient)", 0) == 0;
  }
  EXPECT_EQ(named, 3u);  // the taper, the two-element Windkessel and the momentum flux
  EXPECT_TRUE(told_taper);
  EXPECT_TRUE(told_split);
  EXPECT_TRUE(told_alpha);
}

// openBF 2.x's code reads "gamma_profile" only: "gamma profile" (1.x's spelling, as the circle
// of Willis has it) leaves its default 2, a parabolic profile and friction 8 pi mu.
TEST_F(OpenbfTest, TheSpacedGammaProfileIsReadOnlyAsDocumented) {
  file("tee_inlet.dat", inlet_table);
  std::string text = three_vessels;
  for (std::size_t at; (at = text.find("gamma_profile")) != std::string::npos;) text.replace(at, 13, "gamma profile");
  file("spaced.yaml", text);
  options_.note = [this](const std::string& s) { notes_.push_back(in_words(s, vimport_words())); };  // as vimport words them
  EXPECT_DOUBLE_EQ(read_openbf(path("spaced.yaml"), options_).blood->alpha, 4.0 / 3.0);
  bool told = false;
  for (const std::string& n : notes_)
    told |= n.rfind("\"gamma profile\" (openBF 1.x's spelling) on 3 vessels: not read by openBF 2.x's code", 0) == 0 &&
            n.find("--as-documented") != std::string::npos;
  EXPECT_TRUE(told);
  const Network documented = read_openbf(path("spaced.yaml"), options_, OpenbfReading::documented);
  EXPECT_DOUBLE_EQ(documented.blood->alpha, 1.1);
  EXPECT_EQ(documented.blood->momentum_alpha(), 1.1);  // as documented, one profile for flux and friction
}

// The inlet file is found beside the model, whatever the working folder.
TEST_F(OpenbfTest, DefaultInletFileIsProjectNameBesideTheModel) {
  std::string text = three_vessels;
  text.erase(text.find("inlet_file: tee_inlet.dat\n"), std::string("inlet_file: tee_inlet.dat\n").size());
  file("tee_inlet.dat", inlet_table);
  const Network net = read_openbf(file("model.yaml", text), options_);
  EXPECT_EQ(net.inlet->waveform.time.size(), 3u);
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  if (at == std::string::npos) throw std::logic_error("no " + from);
  return text.replace(at, from.size(), to);
}

TEST_F(OpenbfTest, RefusesMalformedModelsNamingFileLineAndKey) {
  file("tee_inlet.dat", inlet_table);
  const std::string p = path("m.yaml");

  // Bad YAML: a flow sequence opened on line 5 and never closed, found at the end (line 6).
  file("m.yaml", "project_name: m\nblood:\n  rho: 1060.0\nnetwork:\n  - {label: a, sn: [1, 2\n");
  const std::string syntax = refusal(p);
  EXPECT_EQ(syntax.rfind(p + ":", 0), 0u) << syntax;
  EXPECT_NE(syntax.find("not valid YAML"), std::string::npos) << syntax;
  EXPECT_NE(syntax.find(":6: not valid YAML: end of sequence flow not found"), std::string::npos) << syntax;

  // The vessel's mapping starts on line 22 ("label: left").
  file("m.yaml", replaced(three_vessels, "    L: 0.05\n    E: 600000.0", "    E: 600000.0"));
  EXPECT_EQ(refusal(p), p + ":22: vessel 2: missing \"L\"");

  file("m.yaml", replaced(three_vessels, "R0: 0.004", "R0: -0.004"));
  EXPECT_EQ(refusal(p), p + ":27: vessel 2: \"R0\" must lie in [1e-6, 0.25] m (got -0.004)");

  file("m.yaml", replaced(three_vessels, "    M: 100\n", "    M: 100\n    visco-elastic: true\n"));
  EXPECT_EQ(refusal(p), p + ":21: vessel 1: a visco-elastic wall (\"visco-elastic\": true) is not modelled by hemotree");

  file("m.yaml", replaced(three_vessels, "    M: 100\n", "    M: 100\n    stenosis: 0.5\n"));
  EXPECT_EQ(refusal(p), p + ":21: vessel 1: \"stenosis\" is not an openBF vessel key that hemotree reads or may safely ignore");

  file("m.yaml", replaced(three_vessels, "    R0: 0.003\n    gamma_profile: 9", "    R0: 0.003\n    gamma_profile: 2"));
  EXPECT_EQ(refusal(p), p + ":40: vessel 3: gamma_profile 2 differs from vessel 1's 9: hemotree has one velocity "
                            "profile (blood alpha) for the network");

  file("m.yaml", replaced(three_vessels, "    R1: 2.0e9", "    R1: 1.0e8"));
  EXPECT_EQ(refusal(p).rfind(p + ":42: vessel 3: \"R1\" 1e8 Pa s/m^3 of a two-element Windkessel is not above", 0), 0u)
      << refusal(p);

  file("m.yaml", replaced(three_vessels, "    R1: 1.0e8\n", ""));
  EXPECT_EQ(refusal(p), p + ":22: vessel 2: a Windkessel outlet needs \"R1\"");

  file("m.yaml", replaced(three_vessels, "  mu: 0.004\n", "  mu: 0.004\n  hematocrit: 0.45\n"));
  EXPECT_EQ(refusal(p), p + ":12: blood: \"hematocrit\" is not an openBF blood key (rho, mu)");

  file("m.yaml", replaced(three_vessels, "    tn: 3\n", "    tn: 1\n"));
  EXPECT_EQ(refusal(p), p + ":22: vessel 2: ends at the inlet node 1");
}

TEST_F(OpenbfTest, AMissingInletFileIsAnIoError) {
  EXPECT_THROW(read_openbf(file("tee.yaml", three_vessels), options_), IoError);
  EXPECT_THROW(read_openbf(path("absent.yaml"), options_), IoError);
}

TEST_F(OpenbfTest, RefusesABadInletTableNamingItsLine) {
  file("tee_inlet.dat", "0.0 0.0\n0.5 1e-4\n0.4 0.0\n");
  EXPECT_EQ(refusal(file("tee.yaml", three_vessels)),
            path("tee_inlet.dat") + ":3: times must increase (0.4 s after 0.5 s); the last row's is the period");
  file("tee_inlet.dat", "0.0 0.0\n0.5 1e-4 7\n1.0 0.0\n");
  EXPECT_EQ(refusal(path("tee.yaml")), path("tee_inlet.dat") + ":2: expected two numbers, t [s] and Q [m^3/s]");
  file("tee_inlet.dat", "0.1 0.0\n0.5 1e-4\n1.0 0.0\n");
  EXPECT_EQ(refusal(path("tee.yaml")), path("tee_inlet.dat") + ":1: openBF's inlet table starts at t = 0 (got 0.1 s)");
}

// openBF interpolates between a row and the next (boundary_conditions.jl), so two rows, t = 0
// and the period, are a table it reads: with one flow, a constant inflow (what vexport writes
// for one). One row is not.
TEST_F(OpenbfTest, ReadsATwoRowTableAndRefusesOneRow) {
  file("tee_inlet.dat", "0.0 2.5e-6\n0.8 2.5e-6\n");
  const Network net = read_openbf(file("tee.yaml", three_vessels), options_);
  EXPECT_DOUBLE_EQ(net.inlet->waveform.period, 0.8);
  EXPECT_EQ(net.inlet->waveform.time, (std::vector<double>{0.0, 0.4}));
  EXPECT_EQ(net.inlet->waveform.value, (std::vector<double>{2.5e-6, 2.5e-6}));
  EXPECT_DOUBLE_EQ(net.inlet->waveform.mean_value(), 2.5e-6);
  file("tee_inlet.dat", "0.0 2.5e-6\n");
  EXPECT_EQ(refusal(path("tee.yaml")), path("tee_inlet.dat") + ": an inlet table needs at least 2 rows, t = 0 and the period");
}

// An inlet file that is a device, a folder, too large, or one endless line is refused before it
// is read whole (/dev/zero was read without bound: 1.6 GB and growing).
TEST_F(OpenbfTest, RefusesAnInletFileThatIsNotABoundedTextFile) {
  const std::string model = replaced(three_vessels, "inlet_file: tee_inlet.dat", "inlet_file: /dev/zero");
  EXPECT_EQ(refusal(file("zero.yaml", model)), "/dev/zero: not a regular file; an inlet table is a text file of at most 64 MB");
  fs::create_directories(folder_ / "folder");
  EXPECT_EQ(refusal(file("folder.yaml", replaced(three_vessels, "tee_inlet.dat", "folder"))),
            path("folder") + ": not a regular file; an inlet table is a text file of at most 64 MB");
  // A sparse file just over the cap: refused once the cap is passed, without keeping it.
  { std::ofstream(path("huge.dat")) << "0 0\n"; }
  fs::resize_file(path("huge.dat"), (std::uintmax_t{64} << 20) + 1);
  EXPECT_EQ(refusal(file("huge.yaml", replaced(three_vessels, "tee_inlet.dat", "huge.dat"))),
            path("huge.dat") + ": larger than 64 MB; an inlet table is a text file of at most 64 MB");
  file("tee_inlet.dat", "0 0\n0.5 1e-4" + std::string(5000, ' ') + "\n1 0\n");
  EXPECT_EQ(refusal(file("tee.yaml", three_vessels)),
            path("tee_inlet.dat") + ":2: a line longer than 4096 characters; an inlet table has two numbers a line, t [s] "
                                    "and Q [m^3/s]");
}

// A second YAML document would be dropped: refused, at its line. An empty one drops nothing.
TEST_F(OpenbfTest, RefusesASecondYamlDocument) {
  file("tee_inlet.dat", inlet_table);
  const std::string p = file("two.yaml", std::string(three_vessels) + "---\nproject_name: x\n");
  EXPECT_EQ(refusal(p), p + ":45: a second YAML document (after \"---\"); an openBF model is one document, and hemotree "
                            "reads nothing it would drop");
  EXPECT_EQ(refusal(file("end.yaml", std::string(three_vessels) + "---\n")), "");
}

// Keys are checked in file order, unknown ones first, and repeats found by hashing: 60,000
// top-level keys were compared pairwise (55 s) before the first unknown one was named.
TEST_F(OpenbfTest, RefusesManyKeysAtTheFirstUnknownOne) {
  std::string text;
  for (int k = 0; k < 60000; ++k) text += "key" + std::to_string(k) + ": 1\n";
  const std::string p = file("keys.yaml", text);
  EXPECT_EQ(refusal(p), p + ":1: model: \"key0\" is not an openBF key that hemotree reads or may safely ignore");
  const std::string twice = file("twice.yaml", "project_name: a\nproject_name: b\nsolver: 1\n");
  EXPECT_EQ(refusal(twice), twice + ":2: model: \"project_name\" given twice");
  file("tee_inlet.dat", inlet_table);
  const std::string vessel = file("vessel.yaml", replaced(three_vessels, "    M: 100\n", "    M: 100\n    E: 1.0e6\n"));
  EXPECT_EQ(refusal(vessel), vessel + ":21: vessel 1: \"E\" given twice");
}

// A row earlier than the one before it opens no interval in openBF's interpolation; hemotree
// leaves it out and says how far that is from openBF's reading: here openBF follows the line
// from (0.4 s, 8e-5) to (0.6 s, 6e-5) just after 0.5 s (7e-5 m^3/s), hemotree the one from
// (0.5 s, 1e-4): 3e-5 m^3/s apart, 30 % of the peak 1e-4.
TEST_F(OpenbfTest, LeavesOutRowsThatGoBackInTimeWithANote) {
  file("tee_inlet.dat", "0 0\n0.5 1e-4\n0.4 8e-5\n0.6 6e-5\n1 0\n");
  options_.note = [this](const std::string& s) { notes_.push_back(in_words(s, vimport_words())); };  // as vimport words them
  const Network net = read_openbf(file("tee.yaml", three_vessels), options_);
  EXPECT_EQ(net.inlet->waveform.time, (std::vector<double>{0, 0.5, 0.6}));
  std::string note;
  for (const std::string& n : notes_)
    if (n.find("go back in time") != std::string::npos) note = n;
  EXPECT_EQ(note.rfind("inlet table " + path("tee_inlet.dat") + ": rows 3 go back in time and are left out; the flow "
                       "then differs from openBF's reading by at most 3e-5 m^3/s (30 % of the peak)",
                       0),
            0u)
      << note;
}

void expect_same(const Network& a, const Network& b) {
  ASSERT_EQ(a.vessel_count(), b.vessel_count());
  EXPECT_EQ(a.node_id, b.node_id);
  EXPECT_EQ(a.id, b.id);
  EXPECT_EQ(a.from, b.from);
  EXPECT_EQ(a.to, b.to);
  EXPECT_EQ(a.length, b.length);
  EXPECT_EQ(a.diameter, b.diameter);
  EXPECT_EQ(a.wall_thickness, b.wall_thickness);
  EXPECT_EQ(a.youngs_modulus, b.youngs_modulus);
  EXPECT_EQ(a.generation, b.generation);
  ASSERT_EQ(a.distal_diameter.size(), b.distal_diameter.size());
  for (std::size_t v = 0; v < a.vessel_count(); ++v) {
    EXPECT_EQ(a.is_tapered(v), b.is_tapered(v));
    EXPECT_EQ(a.diameter_at_to(v), b.diameter_at_to(v));
  }
  ASSERT_TRUE(a.blood && b.blood);
  EXPECT_EQ(a.blood->density, b.blood->density);
  EXPECT_EQ(a.blood->newtonian_viscosity, b.blood->newtonian_viscosity);
  EXPECT_EQ(a.blood->alpha, b.blood->alpha);
  ASSERT_TRUE(a.inlet && b.inlet);
  EXPECT_EQ(a.inlet->vessel, b.inlet->vessel);
  EXPECT_EQ(a.inlet->waveform.period, b.inlet->waveform.period);
  EXPECT_EQ(a.inlet->waveform.time, b.inlet->waveform.time);
  EXPECT_EQ(a.inlet->waveform.value, b.inlet->waveform.value);
  ASSERT_EQ(a.outlets.size(), b.outlets.size());
  for (std::size_t k = 0; k < a.outlets.size(); ++k) {
    EXPECT_EQ(a.outlets[k].vessel, b.outlets[k].vessel);
    EXPECT_EQ(a.outlets[k].type, b.outlets[k].type);
    EXPECT_EQ(a.outlets[k].r1, b.outlets[k].r1);
    EXPECT_EQ(a.outlets[k].c, b.outlets[k].c);
    EXPECT_EQ(a.outlets[k].r2, b.outlets[k].r2);
    EXPECT_EQ(a.outlets[k].p_out, b.outlets[k].p_out);
    EXPECT_EQ(a.outlets[k].reflection, b.outlets[k].reflection);
  }
  EXPECT_EQ(a.beta, b.beta);
  EXPECT_EQ(a.reference_pressure, b.reference_pressure);
  EXPECT_EQ(a.provenance["labels"], b.provenance["labels"]);
  EXPECT_EQ(a.provenance["external_pressure"], b.provenance["external_pressure"]);
}

Network round_trip(const Network& net, const std::string& yaml, const std::string& inlet,
                   OpenbfReading reading = OpenbfReading::code) {
  {
    OutputStream out(yaml);
    write_openbf(net, out, inlet);
    out.commit();
  }
  return read_openbf(yaml, ImportOptions{}, reading);
}

TEST_F(OpenbfTest, WritesWhatItReads) {
  file("tee_inlet.dat", inlet_table);
  fs::create_directories(folder_ / "out");
  const Network documented = read_openbf(file("tee.yaml", three_vessels), options_, OpenbfReading::documented);
  expect_same(documented, round_trip(documented, path("out/doc.yaml"), path("out/doc_inlet.dat"), OpenbfReading::documented));
  const Network net = read_openbf(file("tee.yaml", three_vessels), options_);
  const Network back = round_trip(net, path("out/copy.yaml"), path("out/copy_inlet.dat"));
  expect_same(net, back);

  // The inlet file: the table's rows and one at the period repeating t = 0, named relative
  // to the model's folder.
  std::ifstream table(path("out/copy_inlet.dat"));
  std::stringstream rows;
  rows << table.rdbuf();
  EXPECT_EQ(rows.str(), "0.0 0.0\n0.25 1.0e-04\n0.5 4.0e-05\n1.0 0.0\n");
  std::ifstream yaml(path("out/copy.yaml"));
  std::stringstream model;
  model << yaml.rdbuf();
  EXPECT_NE(model.str().find("inlet_file: \"copy_inlet.dat\"\n"), std::string::npos) << model.str();
}

// vexport writes a constant inflow as two rows; vimport reads them back as that flow.
TEST_F(OpenbfTest, AConstantInflowRoundTrips) {
  file("tee_inlet.dat", inlet_table);
  Network net = read_openbf(file("tee.yaml", three_vessels), options_);
  net.inlet->waveform = Waveform::constant_value(1e-7);
  fs::create_directories(folder_ / "out");
  const Network back = round_trip(net, path("out/c.yaml"), path("out/c_inlet.dat"));
  std::ifstream table(path("out/c_inlet.dat"));
  std::stringstream rows;
  rows << table.rdbuf();
  EXPECT_EQ(rows.str(), "0.0 1.0e-07\n1.0 1.0e-07\n");
  for (const double t : {0.0, 0.3, 0.5, 0.99}) EXPECT_DOUBLE_EQ(back.inlet->waveform(t), 1e-7);
  EXPECT_DOUBLE_EQ(back.inlet->waveform.mean_value(), 1e-7);
}

TEST_F(OpenbfTest, RefusesToWriteWhatOpenbfCannotExpress) {
  file("tee_inlet.dat", inlet_table);
  Network net = read_openbf(file("tee.yaml", three_vessels), options_);
  const auto message = [&](const Network& n) -> std::string {
    try {
      OutputStream out(path("w.yaml"));
      write_openbf(n, out, path("w_inlet.dat"));
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  Network with_pressure = net;
  NodeBoundary b;
  b.node = 1;  // node id 2, the junction
  b.type = BoundaryType::pressure;
  b.waveform = Waveform::constant_value(1e4);
  with_pressure.boundaries.push_back(b);
  EXPECT_EQ(message(with_pressure), "node 2: a pressure boundary: openBF prescribes only the inflow at its inlet node");

  Network resistance = net;
  resistance.outlets[0].type = BoundaryType::resistance;
  resistance.outlets[0].r = 1e9;
  EXPECT_EQ(message(resistance), "vessel 2: a resistance (R) outlet; openBF has Windkessels and reflection only");

  Network two_inlets = net;
  NodeBoundary flow;
  flow.node = 2;  // node id 3, where an outlet already is: move that outlet away first
  two_inlets.outlets.erase(two_inlets.outlets.begin());
  flow.type = BoundaryType::flow;
  flow.waveform = Waveform::constant_value(1e-6);
  two_inlets.boundaries.push_back(flow);
  EXPECT_EQ(message(two_inlets), "node 3: a second flow boundary (the first at node 1): openBF has one inlet");
}

// A tube law given by beta becomes openBF's thin wall: E h0 = 3 beta A0 / (4 sqrt(pi)), so that
// openBF's beta = (4/3) sqrt(pi) E h0 / A0 is the one given; its reference pressure is Pext.
TEST_F(OpenbfTest, WritesATubeLawGivenByBetaAsYoungsModulus) {
  file("tee_inlet.dat", inlet_table);
  Network net = read_openbf(file("tee.yaml", three_vessels), options_);
  net.beta = {std::nan(""), 3.2e6, 5.1e6};
  net.reference_pressure = {std::nan(""), 0.0, 0.0};
  fs::create_directories(folder_ / "out");
  const Network back = round_trip(net, path("out/b.yaml"), path("out/b_inlet.dat"));
  for (std::size_t v = 1; v < 3; ++v) {
    const double a0 = std::numbers::pi * net.diameter[v] * net.diameter[v] / 4;
    EXPECT_NEAR(4.0 / 3.0 * std::sqrt(std::numbers::pi) * back.youngs_modulus[v] * back.wall_thickness[v] / a0,
                net.beta[v], 1e-12 * net.beta[v]);
    EXPECT_EQ(back.wall_thickness[v], net.wall_thickness[v]);
  }
  EXPECT_EQ(back.youngs_modulus[0], net.youngs_modulus[0]);

  net.reference_pressure = {std::nan(""), 1e4, 1e4};
  try {
    OutputStream out(path("out/c.yaml"));
    write_openbf(net, out, path("out/c_inlet.dat"));
    ADD_FAILURE() << "written";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "vessel 1: no beta, where vessel 2's reference_pressure 10000 Pa would become openBF's Pext "
                           "for every vessel");
  }
}

// --- the models openBF ships -------------------------------------------------------------------

fs::path networks_dir() { return shared_networks_dir(); }

struct Shipped {
  const char* path;
  std::size_t vessels, nodes, tapered, outlets;
};

// Counted from the files: vessels (list items), nodes (distinct sn/tn), tapered (Rp != Rd: as
// documented; openBF's code keeps them at Rp), outlets (vessels whose tn no vessel leaves,
// each with R1 and Cc).
const Shipped shipped[] = {
    {"openbf/alastruey2007/circle_of_willis.yaml", 33, 30, 0, 11},
    {"openbf/boileau2015/adan56/adan56.yaml", 77, 78, 39, 31},
    {"openbf/matthys2007/invitro_model.yaml", 37, 38, 22, 16},
};

TEST_F(OpenbfTest, ReadsAndRoundTripsTheShippedModels) {
  if (!fs::exists(networks_dir() / "openbf")) GTEST_SKIP() << "no " << networks_dir() << "/openbf";
  for (const Shipped& s : shipped)
    for (const OpenbfReading reading : {OpenbfReading::code, OpenbfReading::documented}) {
    SCOPED_TRACE(std::string(s.path) + (reading == OpenbfReading::code ? " as coded" : " as documented"));
    const Network net = read_openbf((networks_dir() / s.path).string(), options_, reading);
    EXPECT_EQ(net.vessel_count(), s.vessels);
    EXPECT_EQ(net.node_count(), s.nodes);
    std::size_t tapered = 0;
    for (std::size_t v = 0; v < net.vessel_count(); ++v) tapered += net.is_tapered(v);
    EXPECT_EQ(tapered, reading == OpenbfReading::code ? 0u : s.tapered);
    EXPECT_EQ(net.outlets.size(), s.outlets);
    for (const Outlet& o : net.outlets) {
      EXPECT_EQ(o.type, BoundaryType::rcr);
      EXPECT_GT(o.r1, 0);
      EXPECT_GT(o.r2, 0);
    }
    ASSERT_TRUE(net.inlet);
    EXPECT_EQ(net.node_id[net.from[static_cast<std::size_t>(net.index_of(net.inlet->vessel))]], 1);
    const Network back = round_trip(net, path("copy.yaml"), path("copy_inlet.dat"), reading);
    expect_same(net, back);
  }
}

TEST_F(OpenbfTest, TheCircleOfWillisClosesLoopsAndAdan56HasItsOwnExternalPressure) {
  if (!fs::exists(networks_dir() / "openbf")) GTEST_SKIP() << "no " << networks_dir() << "/openbf";
  const Network willis = read_openbf((networks_dir() / shipped[0].path).string(), options_);
  // Independent cycles of a connected graph: vessels - nodes + 1 (33 - 30 + 1).
  EXPECT_EQ(static_cast<long>(willis.vessel_count()) - static_cast<long>(willis.node_count()) + 1, 4);
  // "gamma profile: 9", openBF 1.x's spelling: openBF 2.x's code reads its default 2.
  EXPECT_DOUBLE_EQ(willis.blood->alpha, 4.0 / 3.0);
  EXPECT_DOUBLE_EQ(read_openbf((networks_dir() / shipped[0].path).string(), options_, OpenbfReading::documented)
                       .blood->alpha,
                   1.1);

  // Its 11 outlets give R1 and Cc only. openBF's code: R1 stays, R2 = R1 - Z, Z = rho c0 / A0
  // of the thin wall (c0^2 = 2 E h / (3 rho R), h from Avolio's law as he published it); the
  // documented reading splits R1 into Z and R1 - Z. Both share R2, and the code's R1 is the
  // documented total.
  const Network documented =
      read_openbf((networks_dir() / shipped[0].path).string(), options_, OpenbfReading::documented);
  ASSERT_EQ(willis.outlets.size(), 11u);
  for (std::size_t k = 0; k < willis.outlets.size(); ++k) {
    const Outlet &code = willis.outlets[k], &doc = documented.outlets[k];
    const auto v = static_cast<std::size_t>(code.vessel);
    const double r = willis.diameter[v] / 2, h = avolio_wall_m(r), e = willis.youngs_modulus[v];
    const double z = 1060 * std::sqrt(2 * e * h / (3 * 1060 * r)) / (std::numbers::pi * r * r);
    EXPECT_DOUBLE_EQ(willis.blood->density, 1060);
    EXPECT_NEAR(doc.r1, z, 1e-9 * z);
    EXPECT_EQ(code.r1, doc.r1 + doc.r2);
    EXPECT_NEAR(code.r2, code.r1 - z, 1e-9 * code.r1);
    EXPECT_EQ(code.r2, doc.r2);
  }

  const Network adan = read_openbf((networks_dir() / shipped[1].path).string(), options_);
  EXPECT_DOUBLE_EQ(adan.provenance["external_pressure"].get<double>(), 1e4);
  EXPECT_DOUBLE_EQ(adan.blood->alpha, 4.0 / 3.0);  // gamma_profile 2
  // The inlet table: 22 rows from 0 to 1 s, the last dropped.
  EXPECT_DOUBLE_EQ(adan.inlet->waveform.period, 1.0);
  EXPECT_EQ(adan.inlet->waveform.time.size(), 21u);
}

}  // namespace

// Fuzzing found that yaml-cpp 0.7 makes no progress on a ',' where a document should start,
// returning one empty document after another at the same place: YAML::LoadAll then allocated
// until memory ran out. The model's documents are walked by their events and refused there.
TEST_F(OpenbfTest, RefusesYamlWhoseParserMakesNoProgress) {
  for (const std::string& text : {std::string(",a"), std::string("[1]\n,"), std::string("project_name: x\n---\n,")}) {
    const std::string message = refusal(file("stall.yaml", text));
    EXPECT_TRUE(message.find("not valid YAML") != std::string::npos ||
                message.find("second YAML document") != std::string::npos)
        << text << ": " << message;
  }
}
