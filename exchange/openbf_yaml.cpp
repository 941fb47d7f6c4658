// openBF's model file, read with bounds and parsed as one YAML document.
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <yaml-cpp/eventhandler.h>

#include "exchange/openbf_model.hpp"

namespace hemotree::openbf {

namespace fs = std::filesystem;

std::string read_capped(const std::string& path, const std::string& named, const std::string& kind, std::size_t cap) {
  const std::string limit = kind + " is a text file of at most " + std::to_string(cap >> 20) + " MB";
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (error || !fs::exists(status))
    throw IoError("cannot read " + named + ": " + (error ? error.message() : std::string("no such file")));
  // Before opening: opening a pipe waits for a writer.
  if (!fs::is_regular_file(status)) throw InputError(path + ": not a regular file; " + limit);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError("cannot read " + named + ": " + std::strerror(errno));
  std::string text;
  std::vector<char> block(1 << 16);
  while (in) {
    in.read(block.data(), static_cast<std::streamsize>(block.size()));
    const auto got = static_cast<std::size_t>(in.gcount());
    if (text.size() + got > cap) throw InputError(path + ": larger than " + std::to_string(cap >> 20) + " MB; " + limit);
    text.append(block.data(), got);
  }
  if (in.bad()) throw IoError("cannot read " + named + ": " + std::strerror(errno));
  return text;
}

namespace {

// What a document holds, as the parser's events tell it: whether it has any content, where it
// starts and where its last event lies (to see that the parser moves on).
struct DocumentScan : YAML::EventHandler {
  bool content = false;
  YAML::Mark first_content, last;
  void seen(const YAML::Mark& m, bool is_content) {
    last = m;
    if (is_content && !content) first_content = m;
    content |= is_content;
  }
  void OnDocumentStart(const YAML::Mark& m) override { seen(m, false); }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& m, YAML::anchor_t) override { seen(m, false); }
  void OnAlias(const YAML::Mark& m, YAML::anchor_t) override { seen(m, true); }
  void OnScalar(const YAML::Mark& m, const std::string&, YAML::anchor_t, const std::string&) override { seen(m, true); }
  void OnSequenceStart(const YAML::Mark& m, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
    seen(m, true);
  }
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark& m, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
    seen(m, true);
  }
  void OnMapEnd() override {}
};
}  // namespace

// The model: one YAML document. A second one (after "---") would be dropped, so it is refused.
// The documents are walked by the parser's events rather than YAML::LoadAll: yaml-cpp 0.7 makes
// no progress on a ',' where a document should start (",a"), returning one more empty document
// at the same place for ever, and LoadAll then allocated until memory ran out (fuzzing found it).
YAML::Node load_yaml(const std::string& path) {
  const std::string text = read_capped(path, path, "an openBF model", model_cap);
  YAML::Node model;
  try {
    model = YAML::Load(text);
    std::istringstream in(text);
    YAML::Parser parser(in);
    int previous = -1;  // where the last document's last event lay
    for (std::size_t k = 0;; ++k) {
      DocumentScan scan;
      if (!parser.HandleNextDocument(scan)) break;
      if (k > 0 && scan.content)
        Source{path}.fail(scan.first_content, "a second YAML document (after \"---\"); an openBF model is one "
                                      "document, and hemotree reads nothing it would drop");
      if (k > 0 && scan.last.pos <= previous)
        Source{path}.fail(scan.last, "not valid YAML: the parser makes no progress here (a ',' or a ']' "
                                     "where a document should start?)");
      previous = scan.last.pos;
    }
  } catch (const YAML::Exception& e) {
    // yaml-cpp's own message carries "yaml-cpp: error at line L, column C: "; keep its reason.
    Source{path}.fail(e.mark, "not valid YAML: " + e.msg);
  }
  return model;
}
}  // namespace hemotree::openbf
