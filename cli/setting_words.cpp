#include "cli/setting_words.hpp"

namespace hemotree {

const SettingWords& hemosolve_words() {
  static const SettingWords words = {
      {"cfl", "--cfl"},
      {"degree", "--degree"},
      {"dt", "--dt"},
      {"elements", "--elements"},
      {"lumped_step", "--lumped-step"},
      {"model", "--model"},
      {"out", "--out"},
      {"pressure_at", "--pressure-at"},
      {"probe", "--probe"},
      {"steady", "--steady"},
      {"threads", "--threads"},
      {"tracer", "--tracer"},
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
  static const SettingWords words = {{"json", "--json"}};
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
