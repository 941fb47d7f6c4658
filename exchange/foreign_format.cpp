#include "exchange/foreign_format.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>

#include "core/errors.hpp"
#include "core/setting_error.hpp"
#include "formats/field_ranges.hpp"
#include "generator/growth_rules.hpp"

namespace hemotree {

std::string read_whole_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError("cannot open " + path + ": " + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw IoError("cannot read " + path);
  return std::move(text).str();
}

void refuse_deep_xml(const std::string& path, std::string_view xml) {
  // The markup is told apart as rapidxml (Boost.PropertyTree's parser) tells it: where the two
  // could differ, rapidxml stops at an error before it nests any deeper.
  const std::size_t n = xml.size();
  const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
  std::size_t depth = 0, line = 1;
  // Moves past the first `end` at or after `from` (to the end of the text when there is none:
  // the parser then says what is unclosed), counting the lines passed.
  auto skip_past = [&](std::size_t from, std::string_view end) {
    const std::size_t at = xml.find(end, from);
    const std::size_t stop = at == std::string_view::npos ? n : at + end.size();
    line += static_cast<std::size_t>(
        std::count(xml.begin() + static_cast<long>(from), xml.begin() + static_cast<long>(stop), '\n'));
    return stop;
  };
  for (std::size_t i = 0; i < n;) {
    if (xml[i] != '<') {
      if (xml[i] == '\n') ++line;
      ++i;
      continue;
    }
    if (xml.compare(i, 4, "<!--") == 0) {
      i = skip_past(i + 4, "-->");
    } else if (xml.compare(i, 9, "<![CDATA[") == 0) {
      i = skip_past(i + 9, "]]>");
    } else if (xml.compare(i, 2, "<?") == 0) {
      i = skip_past(i + 2, "?>");
    } else if (xml.compare(i, 9, "<!DOCTYPE") == 0 && i + 9 < n && space(xml[i + 9])) {
      // Its internal subset [...] may hold '>'.
      std::size_t brackets = 0, j = i + 9;
      for (; j < n && (xml[j] != '>' || brackets > 0); ++j) {
        if (xml[j] == '\n') ++line;
        else if (xml[j] == '[') ++brackets;
        else if (xml[j] == ']' && brackets > 0) --brackets;
      }
      i = j + 1;
    } else if (xml.compare(i, 2, "<!") == 0) {
      i = skip_past(i + 2, ">");  // any other declaration ends at its first '>'
    } else {
      // A tag, to its '>' outside quoted attribute values. A quote opens a value only after
      // '=' (a quote in a name is a character of the name).
      const std::size_t tag_line = line;
      std::size_t j = i + 1;
      bool after_equals = false;
      for (char quote = 0; j < n; ++j) {
        const char c = xml[j];
        if (c == '\n') ++line;
        if (quote != 0) {
          if (c == quote) quote = 0;
        } else if (after_equals && (c == '"' || c == '\'')) {
          quote = c;
          after_equals = false;
        } else if (c == '>') {
          break;
        } else if (c == '=') {
          after_equals = true;
        } else if (!space(c)) {
          after_equals = false;
        }
      }
      if (j >= n) return;  // an unclosed tag: the parser refuses it
      if (xml[i + 1] == '/') {
        if (depth > 0) --depth;
      } else if (xml[j - 1] != '/' && ++depth > xml_depth_cap) {
        std::size_t name_end = i + 1;
        while (name_end < j && name_end < i + 41 && !space(xml[name_end]) && xml[name_end] != '/') ++name_end;
        const std::string name(xml.substr(i + 1, name_end - i - 1));
        throw InputError(path + ":" + std::to_string(tag_line) + ": <" + name + "> lies " + std::to_string(depth) +
                         " elements deep: hemotree reads XML nested at most " + std::to_string(xml_depth_cap) +
                         " deep");
      }
      i = j + 1;
    }
  }
}

void fill_missing_walls(Network& net, const ImportOptions& options) {
  const GrowthRules rules = default_rules();
  std::size_t walls = 0, moduli = 0;
  for (std::size_t v = 0; v < net.vessel_count(); ++v) {
    const double d = net.diameter[v];
    if (std::isnan(net.wall_thickness[v])) {
      net.wall_thickness[v] = options.wall_ratio
                                  ? *options.wall_ratio * d
                                  : rules.wall[static_cast<std::size_t>(classify(d))].thickness(d);
      ++walls;
    }
    if (std::isnan(net.youngs_modulus[v])) {
      net.youngs_modulus[v] = options.youngs_modulus ? *options.youngs_modulus : rules.youngs_modulus(d);
      ++moduli;
    }
  }
  const auto count = [](std::size_t n) { return std::to_string(n) + (n == 1 ? " vessel" : " vessels"); };
  if (walls > 0)
    options.note(options.wall_ratio
                     ? "wall thickness h = " + format_number(*options.wall_ratio) + " D for " + count(walls) +
                           " (" + placeholder("wall_ratio") + ")"
                     : "wall thickness from hemotree's per-class wall law (vgen " + placeholder("print_rules") + ") for " +
                           count(walls) + "; " + placeholder("wall_ratio") + " sets h/D");
  if (moduli > 0)
    options.note(options.youngs_modulus
                     ? "Young's modulus " + format_number(*options.youngs_modulus) + " Pa for " + count(moduli) +
                           " (" + placeholder("youngs_modulus") + ")"
                     : "Young's modulus from hemotree's E(D) table (vgen " + placeholder("print_rules") + ") for " +
                           count(moduli) + "; " + placeholder("youngs_modulus") + " sets one");
}

namespace {
void ascii_strings(nlohmann::json& j) {
  if (j.is_string()) {
    std::string s = j.get<std::string>();
    for (char& c : s)
      if (static_cast<unsigned char>(c) >= 0x80) c = '?';
    j = s;
  } else if (j.is_structured()) {
    for (auto& item : j) ascii_strings(item);
  }
}
}  // namespace

void stamp_import_provenance(Network& net, const std::string& format, const std::string& source,
                             const nlohmann::json& parameters) {
  if (!net.provenance.is_object()) net.provenance = nlohmann::json::object();
  net.provenance["tool"] = "vimport";
  net.provenance["version"] = HEMOTREE_VERSION;
  net.provenance["format"] = format;
  net.provenance["source"] = source;
  if (!parameters.empty()) net.provenance["parameters"] = parameters;
  try {
    (void)net.provenance.dump();
  } catch (const nlohmann::json::exception&) {
    ascii_strings(net.provenance);
  }
}

}  // namespace hemotree
