// Library text that names a setting (the degree, the time step, a pressure at a node) does it
// through a placeholder, never through a command-line flag: each tool words the setting as its
// user sets it ("--degree"), a caller from code gets the setting's own name ("degree").
//
// The placeholder is the name between the control characters STX and ETX, which neither a
// library's words nor a user's value (a file name, a quoted flag value) carry, so that
// wording a message can never rewrite what the user wrote.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <string_view>

#include "core/errors.hpp"

namespace hemotree {

// A tool's words for the settings its flags set: {"degree", "--degree"}.
using SettingWords = std::map<std::string, std::string, std::less<>>;

// Where a library's text names setting (a lower-case name: letters, digits, '_').
std::string placeholder(std::string_view setting);

// text with each placeholder worded: words' entry for its setting, or the setting's own name
// where words has none.
std::string in_words(std::string_view text, const SettingWords& words = {});

// The first setting text names ("" where it names none).
std::string first_setting(std::string_view text);

// A value of a setting refused: an InputError whose what() names settings by their own names
// ("degree must be at least 0"); a tool words message() instead ("--degree must be ...").
class SettingError : public InputError {
 public:
  // message names setting (and any other) through placeholder().
  SettingError(std::string setting, std::string message);

  const std::string& setting() const { return setting_; }
  const std::string& message() const { return message_; }  // with its placeholders
  std::string in_words(const SettingWords& words) const { return hemotree::in_words(message_, words); }

 private:
  std::string setting_, message_;
};

// Throws SettingError for the first setting message names, or InputError where it names
// none: for a helper that refuses with a message its callers compose.
[[noreturn]] void throw_input_error(std::string message);

}  // namespace hemotree
