// Each tool's words for the settings the libraries' messages name (core/setting_error.hpp):
// the flag that sets each, as its user types it. The libraries say "degree"; hemosolve's user
// reads "--degree". A tool's table holds the settings its libraries may name to its user,
// including another tool's flag where a message points there (vimport's notes name
// hemosolve's --thick-wall-ratio).
#pragma once

#include "core/setting_error.hpp"

namespace hemotree {

const SettingWords& hemosolve_words();
const SettingWords& vgen_words();
const SettingWords& vprune_words();
const SettingWords& vstats_words();
const SettingWords& vimport_words();

}  // namespace hemotree
