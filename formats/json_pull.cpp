#include "formats/json_pull.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <cfloat>
#include <charconv>
#include <cstring>
#include <limits>
#include <system_error>

#include "core/errors.hpp"

namespace hemotree {

namespace {

// buffer_size: big enough that fread's cost per call vanishes, small enough that memory
// stays flat. max_depth: real documents nest a few levels; the bound keeps memory constant
// even for hostile input such as a gigabyte of '['.
constexpr std::size_t buffer_size = JsonPull::buffer_size;
constexpr std::size_t max_depth = JsonPull::max_depth;

// Byte classes for the hot loops: one table lookup per byte, no branches on ranges.
constexpr std::array<bool, 256> make_string_stop() {
  std::array<bool, 256> table{};
  for (int c = 0; c < 0x20; ++c) table[c] = true;  // raw control characters are errors
  for (int c = 0x80; c < 0x100; ++c) table[c] = true;  // UTF-8 sequences are checked
  table['"'] = true;
  table['\\'] = true;
  return table;
}
constexpr std::array<bool, 256> make_number_char() {
  std::array<bool, 256> table{};
  for (int c = '0'; c <= '9'; ++c) table[c] = true;
  table['-'] = table['+'] = table['.'] = table['e'] = table['E'] = true;
  return table;
}
constexpr std::array<bool, 256> string_stop = make_string_stop();
constexpr std::array<bool, 256> number_char = make_number_char();

inline unsigned char byte(char c) { return static_cast<unsigned char>(c); }
inline bool is_digit(char c) { return c >= '0' && c <= '9'; }

// Word-at-a-time scanning: 8 bytes per step instead of one, and no mispredicted branch
// per byte at the end of a run. Each mask has the high bit set in every byte lane that
// stops the run; lanes above the first stopping lane may be wrong (carries and borrows
// only run upwards), which is harmless since only the first one is used.
constexpr bool little_endian = std::endian::native == std::endian::little;
constexpr std::uint64_t lanes(unsigned char c) { return 0x0101010101010101ull * c; }
constexpr std::uint64_t high_bits = lanes(0x80);

inline std::uint64_t load8(const char* at) {
  std::uint64_t word;
  std::memcpy(&word, at, sizeof word);
  return word;
}
// Lanes holding a byte other than '0'..'9'.
inline std::uint64_t non_digit_lanes(std::uint64_t w) {
  return ((w + lanes(0x46)) | (w - lanes('0')) | w) & high_bits;
}
// Lanes holding '"', '\\', a control byte or a non-ASCII byte (the start of a UTF-8
// sequence, which is checked): where a plain run inside a string ends.
inline std::uint64_t string_stop_lanes(std::uint64_t w) {
  auto zero_lanes = [](std::uint64_t x) { return (x - lanes(1)) & ~x & high_bits; };
  const std::uint64_t below_space = (w - lanes(0x20)) & ~w & high_bits;
  return zero_lanes(w ^ lanes('"')) | zero_lanes(w ^ lanes('\\')) | below_space |
         (w & high_bits);
}
inline const char* first_lane(const char* at, std::uint64_t mask) {
  return at + std::countr_zero(mask) / 8;
}

std::string hex_byte(char c) {
  char hex[8];
  std::snprintf(hex, sizeof hex, "0x%02X", byte(c));
  return hex;
}

// How a byte is named in messages: 'x' when printable, else its hex code.
std::string describe_byte(char c) {
  if (byte(c) >= 0x20 && byte(c) < 0x7f) return std::string{'\'', c, '\''};
  return "byte " + hex_byte(c);
}

std::string quoted_excerpt(std::string_view text) {
  constexpr std::size_t keep = 40;  // enough to recognise, short enough for one line
  if (text.size() <= keep) return "\"" + std::string(text) + "\"";
  return "\"" + std::string(text.substr(0, keep)) + "...\"";
}

void append_utf8(std::string& out, std::uint32_t cp) {
  if (cp < 0x80) {
    out += static_cast<char>(cp);
  } else if (cp < 0x800) {
    out += static_cast<char>(0xC0 | (cp >> 6));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else if (cp < 0x10000) {
    out += static_cast<char>(0xE0 | (cp >> 12));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else {
    out += static_cast<char>(0xF0 | (cp >> 18));
    out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  }
}

// For a valid JSON number that std::from_chars found out of range: true when it is too
// small (rounds to zero), false when too large. Decides by the decimal exponent of the
// first nonzero digit, which is all that matters at the ends of the double range.
bool underflows(std::string_view number) {
  std::size_t i = number[0] == '-' ? 1 : 0;
  long long magnitude = 0;  // decimal exponent of the first nonzero digit, before 'e'
  bool found = false;
  long long int_digits = 0;
  for (; i < number.size() && is_digit(number[i]); ++i) {
    if (!found && number[i] != '0') {
      found = true;
      magnitude = -1;
    }
    if (found) ++magnitude;
    ++int_digits;
  }
  if (i < number.size() && number[i] == '.') {
    ++i;
    for (long long place = -1; i < number.size() && is_digit(number[i]); ++i, --place) {
      if (!found && number[i] != '0') {
        found = true;
        magnitude = place;
      }
    }
  }
  long long exponent = 0;
  if (i < number.size() && (number[i] == 'e' || number[i] == 'E')) {
    ++i;
    const bool negative = number[i] == '-';
    if (number[i] == '-' || number[i] == '+') ++i;
    // Saturate: anything beyond a few thousand is equally out of range.
    for (; i < number.size(); ++i)
      if (exponent < 1'000'000) exponent = exponent * 10 + (number[i] - '0');
    if (negative) exponent = -exponent;
  }
  return magnitude + exponent < 0;
}

// Clinger's fast path: when the decimal mantissa (below 2^53) and the power of ten
// (up to 1e22) are both exact doubles, one IEEE multiply or divide rounds correctly.
// Nearly every number in real data qualifies, and this is several times faster than
// std::from_chars, which remains the fallback. Input is a valid JSON number.
bool fast_double(std::string_view number, double& out) {
  static constexpr double powers_of_ten[] = {
      1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
      1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  if constexpr (FLT_EVAL_METHOD != 0) return false;  // x87 would round twice
  const char* c = number.data();
  const char* const last = c + number.size();
  const bool negative = *c == '-';
  c += negative;
  std::uint64_t mantissa = 0;
  int digits = 0;     // more than 19 could overflow the mantissa
  int exponent = 0;
  for (; c < last && is_digit(*c); ++c, ++digits) mantissa = mantissa * 10 + (*c - '0');
  if (c < last && *c == '.')
    for (++c; c < last && is_digit(*c); ++c, ++digits, --exponent)
      mantissa = mantissa * 10 + (*c - '0');
  if (digits > 19) return false;
  if (c < last) {  // 'e' or 'E'
    ++c;
    const bool negative_exponent = *c == '-';
    if (*c == '-' || *c == '+') ++c;
    int value = 0;
    for (; c < last; ++c) {
      if (value > 1000) return false;  // far outside the fast path anyway
      value = value * 10 + (*c - '0');
    }
    exponent += negative_exponent ? -value : value;
  }
  if (mantissa > (std::uint64_t{1} << 53) || exponent < -22 || exponent > 22) return false;
  double value = static_cast<double>(mantissa);
  value = exponent < 0 ? value / powers_of_ten[-exponent] : value * powers_of_ten[exponent];
  out = negative ? -value : value;
  return true;
}

// RFC 8259 s. 8.1: text is UTF-8, so a string holds only well-formed sequences (RFC 3629
// s. 4: no overlong forms, no encoded surrogates, nothing above U+10FFFF). Checked here
// so that every later consumer (nlohmann::json among them, which throws on bad UTF-8 when
// it writes) can trust the strings. Given the bytes [q, last) of a sequence whose lead
// byte *q is >= 0x80, returns the sequence length and leaves `problem` empty; 0 when the
// bytes end before the sequence does (the caller fetches more); otherwise sets `problem`.
std::size_t utf8_sequence(const char* q, const char* last, std::string& problem) {
  const unsigned char lead = byte(*q);
  std::size_t length = 0;
  unsigned char low = 0x80, high = 0xBF;  // the allowed range of the second byte
  if (lead >= 0xC2 && lead <= 0xDF) {
    length = 2;
  } else if (lead >= 0xE0 && lead <= 0xEF) {
    length = 3;
    if (lead == 0xE0) low = 0xA0;   // below: an overlong form of U+0000..U+07FF
    if (lead == 0xED) high = 0x9F;  // above: the surrogates U+D800..U+DFFF
  } else if (lead >= 0xF0 && lead <= 0xF4) {
    length = 4;
    if (lead == 0xF0) low = 0x90;   // below: an overlong form of U+0000..U+FFFF
    if (lead == 0xF4) high = 0x8F;  // above: beyond U+10FFFF
  } else if (lead < 0xC0) {
    problem = "continuation byte " + hex_byte(*q) + " without a lead byte";
    return 0;
  } else if (lead < 0xC2) {
    problem = "overlong encoding (lead byte " + hex_byte(*q) + ")";
    return 0;
  } else {
    problem = "byte " + hex_byte(*q) + " never occurs in UTF-8";
    return 0;
  }
  for (std::size_t i = 1; i < length; ++i) {
    if (q + i >= last) return 0;
    const unsigned char c = byte(q[i]);
    if (c >= 0x80 && c <= 0xBF && (i > 1 || (c >= low && c <= high))) continue;
    if (i == 1 && c >= 0x80 && c <= 0xBF) {
      problem = lead == 0xED   ? "an encoded UTF-16 surrogate (U+D800..U+DFFF)"
                : lead == 0xF4 ? "a code point above U+10FFFF"
                               : "overlong encoding";
      problem += " (bytes " + hex_byte(q[0]) + " " + hex_byte(q[1]) + ")";
    } else {
      problem = "sequence cut short: lead byte " + hex_byte(q[0]) + " followed by " +
                describe_byte(q[i]);
    }
    return 0;
  }
  return length;
}

}  // namespace

struct JsonPull::Impl {
  // What next() expects, given the tokens so far.
  enum class State : unsigned char {
    top,           // the single top-level value
    array_start,   // a value or ']'
    object_start,  // a key or '}'
    after_key,     // ':' then a value
    after_value,   // ',' or the closing bracket of the innermost container
    after_top,     // only whitespace, then end of input
    finished       // end_of_input was returned
  };

  Impl(std::FILE* stream, std::string name, std::size_t buffer_bytes)
      : in(stream), storage(std::max<std::size_t>(buffer_bytes, 1)), source(std::move(name)) {
    begin = p = end = storage.data();
  }
  Impl(std::string_view text, std::string name) : source(std::move(name)) {
    begin = p = text.data();
    end = begin + text.size();
    exhausted = true;  // nothing to refill: the whole input is in memory
  }

  // --- input ---------------------------------------------------------------------------
  std::FILE* in = nullptr;
  std::vector<char> storage;   // the fixed buffer for stream input
  const char* begin = nullptr;  // current buffer window [begin, end), cursor p
  const char* p = nullptr;
  const char* end = nullptr;
  std::uint64_t base = 0;      // offset in the input of *begin
  bool exhausted = false;      // true once no input remains beyond end
  std::string source;

  // Newlines only occur in whitespace (raw ones in strings are errors), so the line is
  // counted there alone and a column is an offset minus the offset where the line began.
  std::uint64_t line_number = 1;
  std::uint64_t line_start = 0;

  // --- grammar -------------------------------------------------------------------------
  State state = State::top;
  std::vector<unsigned char> in_object;  // per open container: 1 object, 0 array

  // --- current token -------------------------------------------------------------------
  Token token = Token::end_of_input;
  std::string_view text;        // into the buffer, into scratch, or a literal
  bool bool_value = false;
  std::uint64_t token_offset = 0;
  std::string scratch;          // reused for tokens with escapes or across refills
  std::string problem;          // what utf8_sequence found wrong; empty when all is well

  std::uint64_t offset_of(const char* at) const {
    return base + static_cast<std::uint64_t>(at - begin);
  }

  [[noreturn]] void error_at(std::uint64_t offset, const std::string& message) const {
    throw JsonError(source + ":" + std::to_string(line_number) + ":" +
                    std::to_string(offset - line_start + 1) + ": " + message);
  }

  // "<what>, found <the byte at p or end of input>", at p.
  [[noreturn]] void fail_found(const char* what) const {
    error_at(offset_of(p),
             std::string(what) + ", found " + (p < end ? describe_byte(*p) : "end of input"));
  }

  // Loads the next chunk of a stream. Call only when everything before end is consumed.
  bool refill() {
    if (exhausted) return false;
    base += static_cast<std::uint64_t>(end - begin);
    const std::size_t n = std::fread(storage.data(), 1, storage.size(), in);
    p = begin;
    end = begin + n;
    if (n == 0) {
      if (std::ferror(in)) throw IoError("cannot read " + source + ": " + std::strerror(errno));
      exhausted = true;
      return false;
    }
    return true;
  }

  // Leaves p at the next non-whitespace byte; false at end of input.
  bool skip_whitespace() {
    for (;;) {
      while (p < end) {
        const char c = *p;
        if (byte(c) > ' ') return true;  // the common case: tokens packed without blanks
        if (c == ' ' || c == '\t' || c == '\r') {
          ++p;
        } else if (c == '\n') {
          ++p;
          ++line_number;
          line_start = offset_of(p);
        } else {
          return true;  // another control byte: the caller reports it
        }
      }
      if (!refill()) return false;
    }
  }

  // --- tokens --------------------------------------------------------------------------

  // End of the run of digits starting at q (bounded by the buffer).
  const char* skip_digits(const char* q) const {
    if constexpr (little_endian) {
      for (; end - q >= 8; q += 8)
        if (const std::uint64_t stop = non_digit_lanes(load8(q))) return first_lane(q, stop);
    }
    while (q < end && is_digit(*q)) ++q;
    return q;
  }

  // End of the run of bytes starting at q that a string copies verbatim.
  const char* skip_plain(const char* q) const {
    if constexpr (little_endian) {
      for (; end - q >= 8; q += 8)
        if (const std::uint64_t stop = string_stop_lanes(load8(q))) return first_lane(q, stop);
    }
    while (q < end && !string_stop[byte(*q)]) ++q;
    return q;
  }

  Token after_scalar(Token t) {
    state = in_object.empty() ? State::after_top : State::after_value;
    return token = t;
  }

  Token open(bool object) {
    token_offset = offset_of(p);
    if (in_object.size() >= max_depth)
      error_at(token_offset, "nesting deeper than " + std::to_string(max_depth) + " levels");
    ++p;
    in_object.push_back(object);
    state = object ? State::object_start : State::array_start;
    text = object ? "{" : "[";
    return token = object ? Token::begin_object : Token::begin_array;
  }

  Token close(bool object) {
    token_offset = offset_of(p);
    ++p;
    in_object.pop_back();
    text = object ? "}" : "]";
    return after_scalar(object ? Token::end_object : Token::end_array);
  }

  // With p at a value's first byte, reads that value's first token.
  Token value(const char* expected) {
    token_offset = offset_of(p);
    switch (*p) {
      case '{': return open(true);
      case '[': return open(false);
      case '"':
        scan_string();
        return after_scalar(Token::string);
      case '-': case '0': case '1': case '2': case '3': case '4':
      case '5': case '6': case '7': case '8': case '9':
        scan_number();
        return after_scalar(Token::number);
      case 't':
        scan_literal("true");
        bool_value = true;
        return after_scalar(Token::boolean);
      case 'f':
        scan_literal("false");
        bool_value = false;
        return after_scalar(Token::boolean);
      case 'n':
        scan_literal("null");
        return after_scalar(Token::null);
      default: fail_found(expected);
    }
  }

  Token key() {
    token_offset = offset_of(p);
    scan_string();
    state = State::after_key;
    return token = Token::key;
  }

  // p at the opening quote. The fast path returns a view into the buffer; escapes or a
  // buffer refill inside the string divert to the slow path, which builds scratch.
  void scan_string() {
    const char* start = ++p;
    const char* q = skip_plain(start);
    // Non-ASCII text in the buffer is checked in place; a sequence cut by the buffer's end
    // (or a bad one, which the slow path then reports) leaves the loop.
    while (q < end && byte(*q) >= 0x80) {
      const std::size_t length = utf8_sequence(q, end, problem);
      if (length == 0) break;
      q = skip_plain(q + length);
    }
    if (q < end && *q == '"') {
      text = std::string_view(start, static_cast<std::size_t>(q - start));
      p = q + 1;
      return;
    }
    scratch.assign(start, q);
    p = q;
    scan_string_slow();
  }

  void scan_string_slow() {
    for (;;) {
      if (p == end && !refill()) error_at(offset_of(p), "unexpected end of input inside string");
      const char c = *p;
      if (c == '"') {
        ++p;
        text = scratch;
        return;
      }
      if (c == '\\') {
        ++p;
        unescape(offset_of(p) - 1);
        continue;
      }
      if (byte(c) < 0x20)
        error_at(offset_of(p), "unescaped control character " + hex_byte(c) + " in string");
      if (byte(c) >= 0x80) {
        take_utf8();
        continue;
      }
      const char* q = skip_plain(p);
      scratch.append(p, q);
      p = q;
    }
  }

  // p at a byte >= 0x80 inside a string: checks one UTF-8 sequence, which may be cut by
  // buffer refills, and appends it to scratch. Errors point at the sequence's first byte.
  void take_utf8() {
    const std::uint64_t at = offset_of(p);
    char sequence[4];
    std::size_t have = 0;
    for (;;) {
      if (p == end && !refill())
        error_at(at, "invalid UTF-8 in string: sequence cut short by the end of input");
      sequence[have++] = *p++;
      problem.clear();
      const std::size_t length = utf8_sequence(sequence, sequence + have, problem);
      if (!problem.empty()) error_at(at, "invalid UTF-8 in string: " + problem);
      if (length != 0) {
        scratch.append(sequence, length);
        return;
      }
    }
  }

  // The next raw byte inside a string, refilling as needed (slow path only).
  char take() {
    if (p == end && !refill()) error_at(offset_of(p), "unexpected end of input inside string");
    return *p++;
  }

  // p just past a backslash at offset `at`; appends the escaped character to scratch.
  void unescape(std::uint64_t at) {
    const char c = take();
    switch (c) {
      case '"': scratch += '"'; return;
      case '\\': scratch += '\\'; return;
      case '/': scratch += '/'; return;
      case 'b': scratch += '\b'; return;
      case 'f': scratch += '\f'; return;
      case 'n': scratch += '\n'; return;
      case 'r': scratch += '\r'; return;
      case 't': scratch += '\t'; return;
      case 'u': break;
      default:
        if (byte(c) >= 0x20 && byte(c) < 0x7f)
          error_at(at, std::string("invalid escape '\\") + c + "' in string");
        error_at(at, "invalid escape: backslash followed by " + describe_byte(c));
    }
    std::uint32_t cp = hex4();
    if (cp >= 0xDC00 && cp <= 0xDFFF)
      error_at(at, "unpaired low surrogate in \\u escape");
    if (cp >= 0xD800 && cp <= 0xDBFF) {
      // UTF-16 beyond the BMP: a high surrogate must be followed by an escaped low one.
      if (take() != '\\' || take() != 'u')
        error_at(at, "high surrogate in \\u escape not followed by a low surrogate");
      const std::uint64_t low_at = offset_of(p) - 2;
      const std::uint32_t low = hex4();
      if (low < 0xDC00 || low > 0xDFFF)
        error_at(low_at, "high surrogate in \\u escape not followed by a low surrogate");
      cp = 0x10000 + ((cp - 0xD800) << 10) + (low - 0xDC00);
    }
    append_utf8(scratch, cp);
  }

  std::uint32_t hex4() {
    std::uint32_t cp = 0;
    for (int i = 0; i < 4; ++i) {
      const char c = take();
      std::uint32_t digit;
      if (c >= '0' && c <= '9') digit = static_cast<std::uint32_t>(c - '0');
      else if (c >= 'a' && c <= 'f') digit = static_cast<std::uint32_t>(c - 'a' + 10);
      else if (c >= 'A' && c <= 'F') digit = static_cast<std::uint32_t>(c - 'A' + 10);
      else error_at(offset_of(p) - 1, "expected 4 hex digits after \\u, found " + describe_byte(c));
      cp = cp * 16 + digit;
    }
    return cp;
  }

  // p at '-' or a digit. The fast path checks the RFC grammar while scanning; a number
  // cut by the end of the buffer, or a malformed one, takes the slow path, which gathers
  // the whole run of number-like bytes and checks it as one piece.
  void scan_number() {
    const char* q = p + (*p == '-');
    const char* digits = q;
    q = skip_digits(q);
    bool ok = q > digits && (*digits != '0' || q == digits + 1);  // no leading zeros
    if (ok && q < end && *q == '.') {
      const char* fraction = ++q;
      q = skip_digits(q);
      ok = q > fraction;
    }
    if (ok && q < end && (*q == 'e' || *q == 'E')) {
      ++q;
      if (q < end && (*q == '+' || *q == '-')) ++q;
      const char* exponent = q;
      q = skip_digits(q);
      ok = q > exponent;
    }
    if (ok && (q < end ? !number_char[byte(*q)] : exhausted)) {
      text = std::string_view(p, static_cast<std::size_t>(q - p));
      p = q;
      return;
    }
    scan_number_slow();
  }

  void scan_number_slow() {
    const char* q = p;
    while (q < end && number_char[byte(*q)]) ++q;
    scratch.assign(p, q);
    p = q;
    while (p == end && refill()) {
      q = p;
      while (q < end && number_char[byte(*q)]) ++q;
      scratch.append(p, q);
      p = q;
    }
    text = scratch;
    check_number();
  }

  // Throws unless text is a number by the RFC grammar:
  // -?(0|[1-9][0-9]*)(\.[0-9]+)?([eE][+-]?[0-9]+)?
  void check_number() const {
    const std::string_view s = text;
    const std::size_t n = s.size();
    std::size_t i = 0;
    // The byte at index i of the token, or the one after it, as named in messages.
    auto found = [&](std::size_t index) {
      return index < n ? describe_byte(s[index]) : p < end ? describe_byte(*p) : "end of input";
    };
    auto fail_at = [&](std::size_t index, const std::string& message) {
      error_at(token_offset + index, message);
    };
    if (s[i] == '-') ++i;
    if (i < n && s[i] == '0') {
      ++i;
      if (i < n && is_digit(s[i])) fail_at(i - 1, "leading zero in number");
    } else if (i < n && is_digit(s[i])) {
      while (i < n && is_digit(s[i])) ++i;
    } else {
      fail_at(i, "expected a digit after '-', found " + found(i));
    }
    if (i < n && s[i] == '.') {
      ++i;
      if (i == n || !is_digit(s[i]))
        fail_at(i, "expected a digit after the decimal point, found " + found(i));
      while (i < n && is_digit(s[i])) ++i;
    }
    if (i < n && (s[i] == 'e' || s[i] == 'E')) {
      ++i;
      if (i < n && (s[i] == '+' || s[i] == '-')) ++i;
      if (i == n || !is_digit(s[i]))
        fail_at(i, "expected a digit in the exponent, found " + found(i));
      while (i < n && is_digit(s[i])) ++i;
    }
    if (i < n) fail_at(i, "unexpected " + found(i) + " in number");
  }

  // p at the literal's first byte, which already matches.
  void scan_literal(std::string_view word) {
    if (static_cast<std::size_t>(end - p) >= word.size() &&
        std::memcmp(p, word.data(), word.size()) == 0) {
      p += word.size();
    } else {
      // Short buffer or a mismatch: compare byte by byte to find the offending one.
      for (char expected : word) {
        if (p == end && !refill())
          error_at(offset_of(p), "unexpected end of input in literal, expected '" +
                                     std::string(word) + "'");
        if (*p != expected)
          error_at(offset_of(p), "invalid literal, expected '" + std::string(word) +
                                     "', found " + describe_byte(*p));
        ++p;
      }
    }
    text = word;
  }

  // --- the state machine ---------------------------------------------------------------

  // One token per call: the separators before it (',' or ':') are checked on the way.
  // fail_found throws, so no case falls through to the next.
  Token next() {
    switch (state) {
      case State::after_value:
        if (in_object.back()) {
          if (!skip_whitespace()) fail_found("expected ',' or '}' after object member");
          if (*p == ',') {
            ++p;
            if (!skip_whitespace() || *p != '"') fail_found("expected a string key after ','");
            return key();
          }
          if (*p == '}') return close(true);
          fail_found("expected ',' or '}' after object member");
        } else {
          if (!skip_whitespace()) fail_found("expected ',' or ']' after array element");
          if (*p == ',') {
            ++p;
            if (!skip_whitespace()) fail_found("expected a value after ','");
            return value("expected a value after ','");
          }
          if (*p == ']') return close(false);
          fail_found("expected ',' or ']' after array element");
        }
      case State::after_key:
        if (!skip_whitespace() || *p != ':') fail_found("expected ':' after object key");
        ++p;
        if (!skip_whitespace()) fail_found("expected a value after ':'");
        return value("expected a value after ':'");
      case State::object_start:
        if (!skip_whitespace()) fail_found("expected a string key or '}'");
        if (*p == '"') return key();
        if (*p == '}') return close(true);
        fail_found("expected a string key or '}'");
      case State::array_start:
        if (!skip_whitespace()) fail_found("expected a value or ']'");
        if (*p == ']') return close(false);
        return value("expected a value or ']'");
      case State::top:
        if (!skip_whitespace()) fail_found("expected a value");
        return value("expected a value");
      case State::after_top:
        if (skip_whitespace()) fail_found("expected end of input after the top-level value");
        state = State::finished;
        token_offset = offset_of(p);
        text = {};
        return token = Token::end_of_input;
      case State::finished:
        return token;
    }
    return token;  // unreachable; keeps -Wreturn-type quiet
  }

  // --- conversions ---------------------------------------------------------------------

  std::string describe_token() const {
    switch (token) {
      case Token::begin_object: return "'{'";
      case Token::end_object: return "'}'";
      case Token::begin_array: return "'['";
      case Token::end_array: return "']'";
      case Token::key: return "key " + quoted_excerpt(text);
      case Token::string: return "string " + quoted_excerpt(text);
      case Token::number: return "number " + std::string(text);
      case Token::boolean: return bool_value ? "true" : "false";
      case Token::null: return "null";
      case Token::end_of_input: return "end of input";
    }
    return "unknown token";
  }

  [[noreturn]] void fail(const std::string& message) const { error_at(token_offset, message); }

  void require(Token wanted, const char* what) const {
    if (token != wanted) fail(std::string("expected ") + what + ", found " + describe_token());
  }

  double to_double() const {
    require(Token::number, "a number");
    double value = 0;
    if (fast_double(text, value)) return value;
    const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ec == std::errc()) return value;
    // from_chars leaves value alone when out of range; tiny numbers round to zero like
    // every IEEE parser does, huge ones have no double and are an error.
    if (underflows(text)) return text[0] == '-' ? -0.0 : 0.0;
    fail("number " + std::string(text) + " is too large for a double");
  }

  std::int64_t to_integer() const {
    require(Token::number, "an integer");
    std::int64_t value = 0;
    const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ptr != text.data() + text.size())
      fail("expected an integer, found number " + std::string(text));
    if (ec != std::errc())
      fail("integer " + std::string(text) + " does not fit in 64 bits");
    return value;
  }

  nlohmann::json to_json_number() const {
    const char* first = text.data();
    const char* last = first + text.size();
    std::int64_t i = 0;
    const auto r = std::from_chars(first, last, i);
    if (r.ptr == last) {
      if (r.ec == std::errc()) return i;
      std::uint64_t u = 0;
      if (*first != '-' && std::from_chars(first, last, u).ec == std::errc()) return u;
    }
    return to_double();
  }

  bool starts_value() const {
    return token != Token::end_object && token != Token::end_array &&
           token != Token::end_of_input && token != Token::key;
  }

  void begin_value(const char* caller) {
    if (token == Token::key) next();
    if (!starts_value())
      fail(std::string(caller) + ": expected the start of a value, found " + describe_token());
  }

  void skip_value() {
    begin_value("skip_value");
    if (token != Token::begin_object && token != Token::begin_array) return;
    std::size_t depth = 1;
    while (depth > 0) {
      switch (next()) {
        case Token::begin_object: case Token::begin_array: ++depth; break;
        case Token::end_object: case Token::end_array: --depth; break;
        default: break;
      }
    }
  }

  // Iterative rather than recursive, so deep nesting cannot overflow the call stack.
  nlohmann::json read_value() {
    begin_value("read_value");
    nlohmann::json root;
    std::vector<nlohmann::json*> open;  // the containers being filled, innermost last
    std::string member;                 // the key of the next object member
    // Puts v where the grammar says it goes; returns where it went.
    auto place = [&](nlohmann::json&& v) -> nlohmann::json& {
      if (open.empty()) return root = std::move(v);
      nlohmann::json& parent = *open.back();
      if (parent.is_array()) {
        parent.push_back(std::move(v));
        return parent.back();
      }
      return parent[member] = std::move(v);  // a repeated key keeps the last value
    };
    for (;;) {
      switch (token) {
        case Token::begin_object: open.push_back(&place(nlohmann::json::object())); break;
        case Token::begin_array: open.push_back(&place(nlohmann::json::array())); break;
        case Token::end_object: case Token::end_array: open.pop_back(); break;
        case Token::key: member.assign(text); break;
        case Token::string: place(std::string(text)); break;
        case Token::number: place(to_json_number()); break;
        case Token::boolean: place(bool_value); break;
        case Token::null: place(nullptr); break;
        case Token::end_of_input: break;  // not reached: next() throws first
      }
      if (open.empty()) return root;
      next();
    }
  }
};

JsonPull::JsonPull(std::FILE* in, std::string source, std::size_t buffer_bytes)
    : impl_(std::make_unique<Impl>(in, std::move(source), buffer_bytes)) {}
JsonPull::JsonPull(std::string_view text, std::string source)
    : impl_(std::make_unique<Impl>(text, std::move(source))) {}
JsonPull::~JsonPull() = default;

JsonPull::Token JsonPull::next() { return impl_->next(); }
JsonPull::Token JsonPull::token() const { return impl_->token; }
std::string_view JsonPull::text() const { return impl_->text; }
double JsonPull::number() const { return impl_->to_double(); }
std::int64_t JsonPull::integer() const { return impl_->to_integer(); }
bool JsonPull::boolean() const {
  impl_->require(Token::boolean, "true or false");
  return impl_->bool_value;
}
void JsonPull::skip_value() { impl_->skip_value(); }
nlohmann::json JsonPull::read_value() { return impl_->read_value(); }
std::size_t JsonPull::line() const { return impl_->line_number; }
std::size_t JsonPull::column() const {
  return static_cast<std::size_t>(impl_->token_offset - impl_->line_start + 1);
}
std::uint64_t JsonPull::offset() const { return impl_->token_offset; }
void JsonPull::fail(const std::string& message) const { impl_->fail(message); }

std::string_view to_string(JsonPull::Token token) {
  switch (token) {
    case JsonPull::Token::begin_object: return "begin_object";
    case JsonPull::Token::end_object: return "end_object";
    case JsonPull::Token::begin_array: return "begin_array";
    case JsonPull::Token::end_array: return "end_array";
    case JsonPull::Token::key: return "key";
    case JsonPull::Token::string: return "string";
    case JsonPull::Token::number: return "number";
    case JsonPull::Token::boolean: return "boolean";
    case JsonPull::Token::null: return "null";
    case JsonPull::Token::end_of_input: return "end_of_input";
  }
  return "unknown";
}

}  // namespace hemotree
