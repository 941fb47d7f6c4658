// A streaming JSON pull parser (RFC 8259) for files of a gigabyte and more.
//
// Why not nlohmann::json's SAX parser: measured at about 60 MB/s here, it needs ~17 s for
// the paper's full tree (1 GB of text); this parser reads through a fixed buffer, checks
// the grammar as it goes and converts numbers with std::from_chars, so memory stays
// constant and the full tree parses in a few seconds. nlohmann::json remains the
// library for small documents (rules, provenance, results) and is the oracle in the tests.
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/errors.hpp"  // JsonError

namespace hemotree {

// Notes: columns count bytes, not UTF-8 characters; the in-memory constructor keeps a view,
// so the text must outlive the parser; a failed read throws IoError (core/errors.hpp); nesting
// is capped at max_depth levels (RFC 8259 s. 9 allows a limit), so hostile input cannot
// exhaust memory; numbers too small for a double become +-0; after a JsonError the parser
// is not to be used again. Before the first next(), token() is end_of_input at 1:1.
class JsonPull {
 public:
  static constexpr std::size_t buffer_size = std::size_t{1} << 20;
  static constexpr std::size_t max_depth = 10000;

  enum class Token {
    begin_object, end_object, begin_array, end_array,
    key,        // an object member's name; text() is the unescaped name
    string,     // text() is the unescaped value
    number,     // text() is the raw number; number() / integer() convert it
    boolean,    // boolean() is the value
    null,
    end_of_input
  };

  // Reads from a stream (not owned) through an internal buffer of buffer_bytes (at least 1;
  // small values exercise every refill path, for tests and fuzzing); source names it in errors.
  JsonPull(std::FILE* in, std::string source, std::size_t buffer_bytes = buffer_size);
  // Parses text held in memory (tests, small documents).
  JsonPull(std::string_view text, std::string source);
  ~JsonPull();
  JsonPull(const JsonPull&) = delete;
  JsonPull& operator=(const JsonPull&) = delete;

  // Advances to the next token, checking the grammar (a single top-level value, commas,
  // colons, matching brackets, nothing but whitespace after the value).
  // Throws JsonError at the first violation, with the position of the offending character.
  Token next();

  Token token() const;
  // Valid until the next call of next(): a key's text dies when its value is read (it may
  // point into the stream buffer, which a refill overwrites, or into a scratch string that a
  // longer escaped string reallocates). Compare it or copy it first. Strings and keys are
  // well-formed UTF-8 (ill-formed bytes are a JsonError at their position).
  std::string_view text() const;
  double number() const;           // the current number token as a double
  std::int64_t integer() const;    // the current number token; JsonError if not an integer
  bool boolean() const;

  // With the current token the start of a value (or a key, then the value after it),
  // consumes that whole value. Afterwards token() is the value's last token.
  void skip_value();
  // Same, but builds the value as nlohmann::json (for small sub-documents).
  nlohmann::json read_value();

  // Position of the current token's first character (1-based line and column).
  std::size_t line() const;
  std::size_t column() const;
  std::uint64_t offset() const;  // byte offset from the start of input, 0-based

  // Throws JsonError with the current token's position prefixed to message.
  [[noreturn]] void fail(const std::string& message) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

std::string_view to_string(JsonPull::Token token);

}  // namespace hemotree
