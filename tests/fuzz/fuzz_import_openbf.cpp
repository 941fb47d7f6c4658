// vimport openbf on hostile bytes. The input is a YAML model, optionally followed by a line
// "#@inlet" and the inlet table's text; the harness writes the model as model.yaml in a
// folder of its own and the table (the input's, else a fixed valid one) under every plain
// file name the model may give it (inlet_file, inlet file, PROJECT_inlet.dat). Odd sizes
// are read as documented (--as-documented), even ones as openBF's code computes.
// An accepted model must be written as vnet and read back the same (vimport's output), and
// what vexport openbf writes of it (model and inlet table) must read back, in the same
// reading, as the same network (docs/import.md: bit-identical for openBF's models; here to
// 1e-12, since beta and E are recomputed). A refusal is InputError, or IoError for an inlet
// file that cannot be read; nothing else.
#include <cctype>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "exchange/openbf.hpp"
#include "import_support.hpp"

using namespace hemotree;
using namespace hemotree::fuzz;

namespace {

constexpr std::string_view inlet_marker = "\n#@inlet\n";
constexpr std::string_view fixed_table = "0.0 1.0e-06\n0.25 3.0e-06\n0.5 2.0e-06\n1.0 1.0e-06\n";

std::string trimmed(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  if (s.size() >= 2 && (s.front() == '"' || s.front() == '\'') && s.back() == s.front()) s = s.substr(1, s.size() - 2);
  return std::string(s);
}

bool plain_name(const std::string& name) {
  if (name.empty() || name.size() > 100 || name == "." || name == ".." || name == "model.yaml" || name == "out") return false;
  for (char c : name)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.')) return false;
  return true;
}

// The inlet file names a model may mean: the values of its inlet keys, PROJECT_inlet.dat.
std::vector<std::string> inlet_names(std::string_view yaml) {
  std::vector<std::string> names{"inlet.dat"};
  std::size_t start = 0;
  while (start < yaml.size()) {
    std::size_t end = yaml.find('\n', start);
    if (end == std::string_view::npos) end = yaml.size();
    std::string_view line = yaml.substr(start, end - start);
    start = end + 1;
    const std::size_t colon = line.find(':');
    if (colon == std::string_view::npos) continue;
    std::string key = trimmed(line.substr(0, colon));
    if (key.rfind("- ", 0) == 0) key = trimmed(std::string_view(key).substr(2));
    const std::string value = trimmed(line.substr(colon + 1));
    if (key == "inlet_file" || key == "inlet file") names.push_back(value);
    if (key == "project_name" || key == "project name") names.push_back(value + "_inlet.dat");
  }
  return names;
}

std::string peer_difference(const Network& a, const Network& b) {
  constexpr double rel = 1e-12;
  if (a.vessel_count() != b.vessel_count()) return "vessel counts differ";
  for (const std::string& d :
       {same("vessel ids", a.id, b.id), same("node ids", a.node_id, b.node_id), same("from", a.from, b.from),
        same("to", a.to, b.to), same("generation", a.generation, b.generation),
        reals("length", a.length, b.length, rel), reals("diameter", a.diameter, b.diameter, rel),
        reals("wall_thickness", a.wall_thickness, b.wall_thickness, rel),
        reals("youngs_modulus", a.youngs_modulus, b.youngs_modulus, rel), reals("beta", a.beta, b.beta, rel),
        reals("reference_pressure", a.reference_pressure, b.reference_pressure, rel, 1e-300)})
    if (!d.empty()) return d;
  for (std::size_t v = 0; v < a.vessel_count(); ++v) {
    if (a.is_tapered(v) != b.is_tapered(v)) return "vessel " + std::to_string(a.id[v]) + " tapered in one only";
    if (!close_enough(a.diameter_at_to(v), b.diameter_at_to(v), rel))
      return "vessel " + std::to_string(a.id[v]) + ": distal diameter differs";
  }
  if (a.blood.has_value() != b.blood.has_value()) return "blood present in one only";
  if (a.blood && !(close_enough(a.blood->density, b.blood->density, rel) &&
                   close_enough(a.blood->newtonian_viscosity, b.blood->newtonian_viscosity, rel) &&
                   close_enough(a.blood->alpha, b.blood->alpha, rel)))
    return "blood differs";
  if (a.inlet.has_value() != b.inlet.has_value()) return "inlet present in one only";
  if (a.inlet) {
    if (a.inlet->vessel != b.inlet->vessel) return "the inlet's vessel differs";
    if (!close_enough(a.inlet->waveform.period, b.inlet->waveform.period, rel)) return "the inlet's period differs";
    if (const std::string d = reals("inlet time", a.inlet->waveform.time, b.inlet->waveform.time, rel, 1e-300);
        !d.empty())
      return d;
    if (const std::string d = reals("inlet flow", a.inlet->waveform.value, b.inlet->waveform.value, rel, 1e-300);
        !d.empty())
      return d;
  }
  if (a.outlets.size() != b.outlets.size()) return "outlet counts differ";
  for (std::size_t k = 0; k < a.outlets.size(); ++k) {
    const Outlet &p = a.outlets[k], &q = b.outlets[k];
    if (p.vessel != q.vessel || p.type != q.type || !close_enough(p.r1, q.r1, rel) || !close_enough(p.r2, q.r2, rel) ||
        !close_enough(p.c, q.c, rel) || !close_enough(p.p_out, q.p_out, rel, 1e-300) ||
        !close_enough(p.reflection, q.reflection, rel, 1e-300))
      return "outlet " + std::to_string(k) + " differs";
  }
  if (a.boundaries.size() != b.boundaries.size()) return "boundary counts differ";
  return "";
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  init_import_harness();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const std::size_t marker = bytes.find(inlet_marker);
  const std::string_view yaml = bytes.substr(0, marker);
  const std::string_view table =
      marker == std::string_view::npos ? fixed_table : bytes.substr(marker + inlet_marker.size());

  // A fresh folder each run: no file of an earlier input may stand in for a missing one.
  const auto folder = scratch() / "model";
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder / "out");
  write_file(folder / "model.yaml", yaml);
  for (const std::string& name : inlet_names(yaml))
    if (plain_name(name)) write_file(folder / name, table);

  const OpenbfReading reading = size % 2 ? OpenbfReading::documented : OpenbfReading::code;
  const auto net = refused_or(
      "read_openbf", [&] { return read_openbf((folder / "model.yaml").string(), quiet_options(), reading); }, true);
  if (!net) return 0;
  check_vnet_round_trip(*net, "openbf");

  // vexport openbf: it may refuse what openBF cannot express; what it writes must read back.
  const auto yaml_out = folder / "out" / "copy.yaml";
  const auto exported = refused_or("write_openbf", [&] {
    OutputStream out(yaml_out.string());
    write_openbf(*net, out, (folder / "out" / "copy_inlet.dat").string());
    out.commit();
    return true;
  });
  if (!exported) return 0;
  const Network back = must("read_openbf refuses what write_openbf wrote",
                            [&] { return read_openbf(yaml_out.string(), quiet_options(), reading); });
  if (const std::string d = peer_difference(*net, back); !d.empty())
    finding("openBF model written by vexport openbf and read back: " + d);
  return 0;
}
