#include "cli/setting_words.hpp"

namespace hemotree {

const SettingWords& hemosolve_words() {
  static const SettingWords words = {
      {"cfl", "--cfl"},
      {"ranks", "the ranks (mpirun -np)"},
      {"checkpoint_every", "--checkpoint-every"},
      {"cycles", "--cycles"},
      {"coupling_passes", "--coupling-passes"},
      {"degree", "--degree"},
      {"dt", "--dt"},
      {"elements", "--elements"},
      {"force", "--force"},
      {"format", "--format"},
      {"frames", "--frames"},
      {"high_degree", "--high-degree"},
      {"linear_error", "--linear-error"},
      {"low_degree", "--low-degree"},
      {"lumped_passes", "--lumped-passes"},
      {"lumped_rc", "--lumped-rc"},
      {"lumped_sections", "--lumped-sections"},
      {"lumped_step", "--lumped-step"},
      {"lumped_transit", "--lumped-transit"},
      {"max_cycles", "--max-cycles"},
      {"settling_degree", "--settling-degree"},
      {"settling_step", "--settling-step"},
      {"mean_flow", "--mean-flow"},  // vprune's
      {"model", "--model"},
      {"out", "--out"},
      {"periodic_harmonics", "--harmonics"},
      {"periodic_tolerance", "--until-periodic"},
      {"pressure_at", "--pressure-at"},
      {"probe", "--probe"},
      {"raise_degree", "--raise-degree"},
      {"red_cells", "--red-cells"},
      {"resume", "--resume"},
      {"rheology", "--rheology"},
      {"sample_interval", "--sample-interval"},
      {"scheme", "--scheme"},
      {"start", "--start"},
      {"steady", "--steady"},
      {"thick_wall_ratio", "--thick-wall-ratio"},
      {"threads", "--threads"},
      {"tracer", "--tracer"},
      {"transport_step", "--transport-step"},
  };
  return words;
}

const SettingWords& vgen_words() {
  static const SettingWords words = {{"min_diameter", "--min-diameter"}};
  return words;
}

const SettingWords& vprune_words() {
  static const SettingWords words = {
      {"capillary_drop", "--capillary-drop"},
      {"mean_flow", "--mean-flow"},
      {"venous_pressure", "--venous-pressure"},
  };
  return words;
}

const SettingWords& vstats_words() {
  static const SettingWords words = {{"json", "--json"}, {"ranks", "--partition"}};
  return words;
}

const SettingWords& vimport_words() {
  static const SettingWords words = {
      {"as_documented", "--as-documented"},
      {"external_pressure", "--external-pressure"},  // hemosolve's
      {"print_rules", "--print-rules"},              // vgen's
      {"radius_array", "--radius-array"},
      {"thick_wall_ratio", "--thick-wall-ratio"},    // hemosolve's
      {"unit", "--unit"},
      {"wall_ratio", "--wall-ratio"},
      {"youngs_modulus", "--youngs-modulus"},
  };
  return words;
}

}  // namespace hemotree
