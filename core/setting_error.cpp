#include "core/setting_error.hpp"

#include <utility>

namespace hemotree {

namespace {
constexpr char open = '\x02', close = '\x03';  // STX name ETX

bool is_name(std::string_view name) {
  if (name.empty()) return false;
  for (const char c : name)
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_')) return false;
  return true;
}
}  // namespace

std::string placeholder(std::string_view setting) {
  std::string text(1, open);
  text += setting;
  text += close;
  return text;
}

std::string in_words(std::string_view text, const SettingWords& words) {
  std::string out;
  out.reserve(text.size());
  std::size_t at = 0;
  while (at < text.size()) {
    const std::size_t start = text.find(open, at);
    const std::size_t end = start == std::string_view::npos ? start : text.find(close, start + 1);
    const std::string_view name = end == std::string_view::npos ? std::string_view() : text.substr(start + 1, end - start - 1);
    if (!is_name(name)) {  // no placeholder further on: the rest as it stands
      const std::size_t stop = start == std::string_view::npos ? text.size() : start + 1;
      out += text.substr(at, stop - at);
      at = stop;
      continue;
    }
    out += text.substr(at, start - at);
    const auto word = words.find(name);
    out += word != words.end() ? std::string_view(word->second) : name;
    at = end + 1;
  }
  return out;
}

std::string first_setting(std::string_view text) {
  for (std::size_t start = text.find(open); start != std::string_view::npos; start = text.find(open, start + 1)) {
    const std::size_t end = text.find(close, start + 1);
    if (end == std::string_view::npos) break;
    if (const std::string_view name = text.substr(start + 1, end - start - 1); is_name(name)) return std::string(name);
  }
  return {};
}

SettingError::SettingError(std::string setting, std::string message)
    : InputError(hemotree::in_words(message)), setting_(std::move(setting)), message_(std::move(message)) {}

void throw_input_error(std::string message) {
  if (std::string setting = first_setting(message); !setting.empty())
    throw SettingError(std::move(setting), std::move(message));
  throw InputError(message);
}

}  // namespace hemotree
