// A minimal XML reader for the tests: elements, attributes and text, enough to check that
// the VTK files we write are well formed and to read their arrays back. No dependency.
#pragma once

#include <cctype>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace hemotree::test_xml {


struct XmlElement {
  std::string name;
  std::map<std::string, std::string> attributes;
  std::string text;
  std::vector<XmlElement> children;

  const XmlElement& data_array(const std::string& array_name) const {
    for (const auto& c : children)
      if (c.name == "DataArray" && c.attributes.at("Name") == array_name) return c;
    throw std::runtime_error("no DataArray " + array_name + " in <" + name + ">");
  }
  const XmlElement& child(const std::string& child_name) const {
    for (const auto& c : children)
      if (c.name == child_name) return c;
    throw std::runtime_error("no <" + child_name + "> in <" + name + ">");
  }
};

class XmlParser {
 public:
  explicit XmlParser(const std::string& text) : s_(text) {}

  XmlElement document() {
    skip_space();
    if (s_.compare(pos_, 5, "<?xml") == 0) pos_ = s_.find("?>", pos_) + 2;
    skip_space();
    XmlElement root = element();
    skip_space();
    if (pos_ != s_.size()) fail("content after the root element");
    return root;
  }

 private:
  XmlElement element() {
    expect('<');
    XmlElement e;
    e.name = name();
    for (;;) {
      skip_space();
      if (peek() == '/') {
        ++pos_;
        expect('>');
        return e;
      }
      if (peek() == '>') {
        ++pos_;
        break;
      }
      std::string key = name();
      expect('=');
      expect('"');
      const auto end = s_.find('"', pos_);
      if (end == std::string::npos) fail("unterminated attribute");
      if (!e.attributes.emplace(key, s_.substr(pos_, end - pos_)).second)
        fail("duplicate attribute " + key);
      pos_ = end + 1;
    }
    for (;;) {
      const auto lt = s_.find('<', pos_);
      if (lt == std::string::npos) fail("unclosed <" + e.name + ">");
      e.text += s_.substr(pos_, lt - pos_);
      pos_ = lt;
      if (s_.compare(pos_, 2, "</") == 0) {
        pos_ += 2;
        if (name() != e.name) fail("mismatched closing tag for <" + e.name + ">");
        skip_space();
        expect('>');
        return e;
      }
      if (s_.compare(pos_, 2, "<!") == 0 || s_.compare(pos_, 2, "<?") == 0)
        fail("unexpected markup");
      e.children.push_back(element());
    }
  }

  std::string name() {
    const auto start = pos_;
    while (pos_ < s_.size() && (std::isalnum(static_cast<unsigned char>(s_[pos_])) ||
                                s_[pos_] == '_' || s_[pos_] == ':' || s_[pos_] == '-'))
      ++pos_;
    if (pos_ == start) fail("expected a name");
    return s_.substr(start, pos_ - start);
  }
  char peek() const { return pos_ < s_.size() ? s_[pos_] : '\0'; }
  void expect(char c) {
    if (peek() != c) fail(std::string("expected '") + c + "'");
    ++pos_;
  }
  void skip_space() {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_]))) ++pos_;
  }
  [[noreturn]] void fail(const std::string& why) const {
    throw std::runtime_error("XML error at byte " + std::to_string(pos_) + ": " + why);
  }

  const std::string& s_;
  std::size_t pos_ = 0;
};

}  // namespace hemotree::test_xml
