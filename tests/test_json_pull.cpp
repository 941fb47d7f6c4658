// Tests of the streaming JSON pull parser: tokens, strings, numbers, whole values, input
// through a FILE* with tokens cut by buffer refills, exact error positions, and an oracle
// comparison with nlohmann::json on random documents.
#include "formats/json_pull.hpp"

#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace {

using hemotree::JsonError;
using hemotree::JsonPull;
using Token = JsonPull::Token;

// The parser reads streams in chunks of this size: the stream tests place tokens across
// the chunk boundaries.
constexpr std::size_t chunk = JsonPull::buffer_size;

// One token as the caller sees it, for comparing two parses.
struct Seen {
  Token token;
  std::string text;
  std::size_t line, column;
  std::uint64_t offset;
  bool operator==(const Seen&) const = default;
};

std::ostream& operator<<(std::ostream& out, const Seen& s) {
  return out << to_string(s.token) << " '" << s.text << "' at " << s.line << ":" << s.column
             << " (" << s.offset << ")";
}

std::vector<Seen> all_tokens(JsonPull& json) {
  std::vector<Seen> seen;
  do {
    json.next();
    seen.push_back({json.token(), std::string(json.text()), json.line(), json.column(),
                    json.offset()});
  } while (json.token() != Token::end_of_input);
  return seen;
}

std::vector<Seen> tokens_in_memory(std::string_view text) {
  JsonPull json(text, "doc.json");
  return all_tokens(json);
}

// Parses text through a FILE* and a buffer of buffer_bytes, as read_network does with files
// and pipes (1 MiB buffers there; tiny ones here put a refill inside every token).
std::vector<Seen> tokens_from_stream(const std::string& text, std::size_t buffer_bytes = chunk) {
  std::FILE* in = text.empty() ? std::tmpfile()
                               : fmemopen(const_cast<char*>(text.data()), text.size(), "r");
  if (!in) throw std::runtime_error("fmemopen failed");
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> closer(in, &std::fclose);
  JsonPull json(in, "doc.json", buffer_bytes);
  return all_tokens(json);
}

// A compact picture of the token sequence, e.g. "{ key:a num:1 }".
std::string summary(std::string_view text) {
  JsonPull json(text, "doc.json");
  std::string out;
  for (Token t = json.next(); t != Token::end_of_input; t = json.next()) {
    if (!out.empty()) out += ' ';
    switch (t) {
      case Token::begin_object: out += '{'; break;
      case Token::end_object: out += '}'; break;
      case Token::begin_array: out += '['; break;
      case Token::end_array: out += ']'; break;
      case Token::key: out += "key:" + std::string(json.text()); break;
      case Token::string: out += "str:" + std::string(json.text()); break;
      case Token::number: out += "num:" + std::string(json.text()); break;
      case Token::boolean: out += json.boolean() ? "true" : "false"; break;
      case Token::null: out += "null"; break;
      case Token::end_of_input: break;
    }
  }
  return out;
}

// The message of the JsonError that parsing text throws, or "no error".
std::string error_of(std::string_view text) {
  try {
    JsonPull json(text, "doc.json");
    while (json.next() != Token::end_of_input) {
    }
  } catch (const JsonError& e) {
    return e.what();
  }
  return "no error";
}

std::string stream_error_of(const std::string& text, std::size_t buffer_bytes = chunk) {
  try {
    tokens_from_stream(text, buffer_bytes);
  } catch (const JsonError& e) {
    return e.what();
  }
  return "no error";
}

// The single string value of a document such as "\"a\\n\"".
std::string string_value(std::string_view text) {
  JsonPull json(text, "doc.json");
  EXPECT_EQ(json.next(), Token::string);
  return std::string(json.text());
}

// --- tokens --------------------------------------------------------------------------

TEST(JsonPullTokens, SmallDocuments) {
  EXPECT_EQ(summary(R"({"a":1,"b":[true,false,null],"c":{},"d":[]})"),
            "{ key:a num:1 key:b [ true false null ] key:c { } key:d [ ] }");
  EXPECT_EQ(summary(" [ [ ] , { \"x\" : \"y\" } ]\r\n"), "[ [ ] { key:x str:y } ]");
  EXPECT_EQ(summary("42"), "num:42");
  EXPECT_EQ(summary("\t\"top\"\n"), "str:top");
  EXPECT_EQ(summary("null"), "null");
  EXPECT_EQ(summary("-0.5e+10"), "num:-0.5e+10");
}

TEST(JsonPullTokens, TextOfEachToken) {
  JsonPull json(R"({"k":[true,null,-1.25E-3]})", "doc.json");
  EXPECT_EQ(json.next(), Token::begin_object);
  EXPECT_EQ(json.text(), "{");
  EXPECT_EQ(json.next(), Token::key);
  EXPECT_EQ(json.text(), "k");
  EXPECT_EQ(json.next(), Token::begin_array);
  EXPECT_EQ(json.next(), Token::boolean);
  EXPECT_EQ(json.text(), "true");
  EXPECT_TRUE(json.boolean());
  EXPECT_EQ(json.next(), Token::null);
  EXPECT_EQ(json.text(), "null");
  EXPECT_EQ(json.next(), Token::number);
  EXPECT_EQ(json.text(), "-1.25E-3");  // raw, as written
  EXPECT_EQ(json.next(), Token::end_array);
  EXPECT_EQ(json.next(), Token::end_object);
  EXPECT_EQ(json.next(), Token::end_of_input);
  EXPECT_EQ(json.text(), "");
  // Past the end it stays at the end.
  EXPECT_EQ(json.next(), Token::end_of_input);
  EXPECT_EQ(json.token(), Token::end_of_input);
}

TEST(JsonPullTokens, PositionsOfTokens) {
  const std::string text = "{\n  \"a\": [1,\r\n     22],\n\t\"b\": null\n}\n";
  JsonPull json(text, "doc.json");
  struct Where { Token token; std::size_t line, column; std::uint64_t offset; };
  const Where expected[] = {
      {Token::begin_object, 1, 1, 0}, {Token::key, 2, 3, 4},      {Token::begin_array, 2, 8, 9},
      {Token::number, 2, 9, 10},      {Token::number, 3, 6, 19},  {Token::end_array, 3, 8, 21},
      {Token::key, 4, 2, 25},         {Token::null, 4, 7, 30},    {Token::end_object, 5, 1, 35},
      {Token::end_of_input, 6, 1, 37}};
  for (const Where& w : expected) {
    EXPECT_EQ(json.next(), w.token);
    EXPECT_EQ(json.line(), w.line) << to_string(w.token);
    EXPECT_EQ(json.column(), w.column) << to_string(w.token);
    EXPECT_EQ(json.offset(), w.offset) << to_string(w.token);
  }
}

TEST(JsonPullTokens, TokenNames) {
  EXPECT_EQ(to_string(Token::begin_object), "begin_object");
  EXPECT_EQ(to_string(Token::end_object), "end_object");
  EXPECT_EQ(to_string(Token::begin_array), "begin_array");
  EXPECT_EQ(to_string(Token::end_array), "end_array");
  EXPECT_EQ(to_string(Token::key), "key");
  EXPECT_EQ(to_string(Token::string), "string");
  EXPECT_EQ(to_string(Token::number), "number");
  EXPECT_EQ(to_string(Token::boolean), "boolean");
  EXPECT_EQ(to_string(Token::null), "null");
  EXPECT_EQ(to_string(Token::end_of_input), "end_of_input");
}

TEST(JsonPullTokens, DeepNestingUpToTheLimit) {
  const std::size_t depth = 10000;
  const std::string ok = std::string(depth, '[') + std::string(depth, ']');
  EXPECT_EQ(error_of(ok), "no error");
  const std::string too_deep = std::string(depth + 1, '[') + std::string(depth + 1, ']');
  EXPECT_EQ(error_of(too_deep), "doc.json:1:10001: nesting deeper than 10000 levels");
}

// --- strings -------------------------------------------------------------------------

TEST(JsonPullStrings, EveryEscape) {
  EXPECT_EQ(string_value(R"("\"")"), "\"");
  EXPECT_EQ(string_value(R"("\\")"), "\\");
  EXPECT_EQ(string_value(R"("\/")"), "/");
  EXPECT_EQ(string_value(R"("\b")"), "\b");
  EXPECT_EQ(string_value(R"("\f")"), "\f");
  EXPECT_EQ(string_value(R"("\n")"), "\n");
  EXPECT_EQ(string_value(R"("\r")"), "\r");
  EXPECT_EQ(string_value(R"("\t")"), "\t");
  EXPECT_EQ(string_value(R"("\u0041\u00e9\u00E9\u20ac\uFFFF")"),
            "A\xC3\xA9\xC3\xA9\xE2\x82\xAC\xEF\xBF\xBF");
  EXPECT_EQ(string_value(R"("\u007f\u0080\u07ff\u0800")"), "\x7F\xC2\x80\xDF\xBF\xE0\xA0\x80");
  EXPECT_EQ(string_value(R"("\u0000")"), std::string(1, '\0'));
  EXPECT_EQ(string_value(R"("a\tb\\c\"d")"), "a\tb\\c\"d");
  EXPECT_EQ(string_value(R"("")"), "");
}

TEST(JsonPullStrings, SurrogatePairs) {
  EXPECT_EQ(string_value(R"("\ud83d\ude00")"), "\xF0\x9F\x98\x80");  // U+1F600
  EXPECT_EQ(string_value(R"("\uD834\uDD1E")"), "\xF0\x9D\x84\x9E");  // U+1D11E
  EXPECT_EQ(string_value(R"("\uDBFF\uDFFF")"), "\xF4\x8F\xBF\xBF");  // U+10FFFF
  EXPECT_EQ(string_value(R"("x\uD800\uDC00y")"), "x\xF0\x90\x80\x80y");  // U+10000
}

TEST(JsonPullStrings, RawUtf8PassesThrough) {
  EXPECT_EQ(string_value("\"h\xC3\xA9mo \xE2\x82\xAC \xF0\x9F\xA9\xB8\""),
            "h\xC3\xA9mo \xE2\x82\xAC \xF0\x9F\xA9\xB8");
}

// RFC 8259 s. 8.1 with RFC 3629 s. 4: the shortest form only, no surrogates, nothing
// above U+10FFFF. Each edge of each range, in memory and through buffers of 1 to 5 bytes
// (which cut every sequence at every byte).
TEST(JsonPullStrings, WellFormedUtf8AtEveryEdgeIsAccepted) {
  const std::string edges[] = {"\xC2\x80", "\xDF\xBF", "\xE0\xA0\x80", "\xEC\xBF\xBF",
                               "\xED\x80\x80", "\xED\x9F\xBF", "\xEE\x80\x80",
                               "\xEF\xBF\xBF", "\xF0\x90\x80\x80", "\xF3\xBF\xBF\xBF",
                               "\xF4\x80\x80\x80", "\xF4\x8F\xBF\xBF"};
  for (const std::string& e : edges) {
    const std::string text = "{\"k" + e + "\":\"a" + e + "b" + e + e + "\\n" + e + "\"}";
    const auto expected = tokens_in_memory(text);
    ASSERT_EQ(expected[1].text, "k" + e);
    ASSERT_EQ(expected[2].text, "a" + e + "b" + e + e + "\n" + e);
    for (std::size_t buffer = 1; buffer <= 5; ++buffer)
      ASSERT_EQ(tokens_from_stream(text, buffer), expected) << "buffer " << buffer;
  }
}

TEST(JsonPullStrings, IllFormedUtf8IsRefusedWithItsPosition) {
  struct Case { std::string bytes, error; };
  const Case cases[] = {
      {"\x80", "continuation byte 0x80 without a lead byte"},
      {"\xBF", "continuation byte 0xBF without a lead byte"},
      {"\xC0\xAF", "overlong encoding (lead byte 0xC0)"},
      {"\xC1\xBF", "overlong encoding (lead byte 0xC1)"},
      {"\xE0\x9F\xBF", "overlong encoding (bytes 0xE0 0x9F)"},
      {"\xF0\x8F\xBF\xBF", "overlong encoding (bytes 0xF0 0x8F)"},
      {"\xED\xA0\x80", "an encoded UTF-16 surrogate (U+D800..U+DFFF) (bytes 0xED 0xA0)"},
      {"\xED\xBF\xBF", "an encoded UTF-16 surrogate (U+D800..U+DFFF) (bytes 0xED 0xBF)"},
      {"\xF4\x90\x80\x80", "a code point above U+10FFFF (bytes 0xF4 0x90)"},
      {"\xF5\x80\x80\x80", "byte 0xF5 never occurs in UTF-8"},
      {"\xFF", "byte 0xFF never occurs in UTF-8"},
      {"\xE2\x82x", "sequence cut short: lead byte 0xE2 followed by 'x'"},
      {"\xC3\"", "sequence cut short: lead byte 0xC3 followed by '\"'"},
      {"\xF0\x9F\x98\xC3\xA9", "sequence cut short: lead byte 0xF0 followed by byte 0xC3"},
  };
  for (const Case& c : cases) {
    // In a value and in a key, after a well-formed sequence; the column is the bad one's.
    for (const std::string& text : {"[\"\xC3\xA9" + c.bytes + "z\"]",
                                    "{\"\xC3\xA9" + c.bytes + "z\":1}"}) {
      const std::string expected = "doc.json:1:5: invalid UTF-8 in string: " + c.error;
      EXPECT_EQ(error_of(text), expected);
      for (std::size_t buffer : {1, 2, 3, 4, 7})
        EXPECT_EQ(stream_error_of(text, buffer), expected) << "buffer " << buffer;
    }
  }
  EXPECT_EQ(error_of("[\"ab\xE2\x82"),
            "doc.json:1:5: invalid UTF-8 in string: sequence cut short by the end of input");
  EXPECT_EQ(stream_error_of("[\"ab\xE2\x82", 3),
            "doc.json:1:5: invalid UTF-8 in string: sequence cut short by the end of input");
  // Outside strings a non-ASCII byte was already a grammar error, and stays one.
  EXPECT_EQ(error_of("[\xC3\xA9]"), "doc.json:1:2: expected a value or ']', found byte 0xC3");
}

TEST(JsonPullStrings, KeysAreUnescapedToo) {
  EXPECT_EQ(summary(R"({"a\u0062c":1})"), "{ key:abc num:1 }");
}

// --- numbers -------------------------------------------------------------------------

// The current number of a one-number document.
double number_of(std::string_view text) {
  JsonPull json(text, "doc.json");
  EXPECT_EQ(json.next(), Token::number);
  return json.number();
}
std::int64_t integer_of(std::string_view text) {
  JsonPull json(text, "doc.json");
  EXPECT_EQ(json.next(), Token::number);
  return json.integer();
}
std::string integer_error_of(std::string_view text) {
  try {
    integer_of(text);
  } catch (const JsonError& e) {
    return e.what();
  }
  return "no error";
}

TEST(JsonPullNumbers, Doubles) {
  EXPECT_EQ(number_of("0"), 0.0);
  EXPECT_EQ(number_of("-12"), -12.0);
  EXPECT_EQ(number_of("0.1"), 0.1);
  EXPECT_EQ(number_of("1.5e3"), 1500.0);
  EXPECT_EQ(number_of("1.5E+3"), 1500.0);
  EXPECT_EQ(number_of("-2.5e-3"), -0.0025);
  EXPECT_EQ(number_of("7.12345678e-06"), 7.12345678e-06);
  EXPECT_EQ(number_of("0.000612345678"), 0.000612345678);
  EXPECT_EQ(number_of("1.7976931348623157e308"), std::numeric_limits<double>::max());
  EXPECT_EQ(number_of("4.9406564584124654e-324"), std::numeric_limits<double>::denorm_min());
  EXPECT_EQ(number_of("123456789012345678901234567890"), 1.2345678901234568e29);
  EXPECT_EQ(number_of("9007199254740993"), 9007199254740992.0);  // 2^53 + 1 rounds to even
  const double negative_zero = number_of("-0");
  EXPECT_EQ(negative_zero, 0.0);
  EXPECT_TRUE(std::signbit(negative_zero));
  // Too small for a double rounds to zero, as in every IEEE parser.
  EXPECT_EQ(number_of("1e-400"), 0.0);
  EXPECT_TRUE(std::signbit(number_of("-1e-400")));
  EXPECT_EQ(number_of("0.0000000000000000000000000000001e-400"), 0.0);
}

TEST(JsonPullNumbers, TooLargeForADouble) {
  JsonPull json("[1e400, 1797693134862315807937289714053034150799e300]", "doc.json");
  json.next();
  json.next();
  EXPECT_THROW(json.number(), JsonError);
  try {
    json.number();
  } catch (const JsonError& e) {
    EXPECT_STREQ(e.what(), "doc.json:1:2: number 1e400 is too large for a double");
  }
  json.next();
  EXPECT_THROW(json.number(), JsonError);
}

TEST(JsonPullNumbers, Integers) {
  EXPECT_EQ(integer_of("0"), 0);
  EXPECT_EQ(integer_of("-0"), 0);
  EXPECT_EQ(integer_of("4015483"), 4015483);
  EXPECT_EQ(integer_of("-42"), -42);
  EXPECT_EQ(integer_of("9223372036854775807"), std::numeric_limits<std::int64_t>::max());
  EXPECT_EQ(integer_of("-9223372036854775808"), std::numeric_limits<std::int64_t>::min());
  EXPECT_EQ(integer_error_of("9223372036854775808"),
            "doc.json:1:1: integer 9223372036854775808 does not fit in 64 bits");
  EXPECT_EQ(integer_error_of("-9223372036854775809"),
            "doc.json:1:1: integer -9223372036854775809 does not fit in 64 bits");
  EXPECT_EQ(integer_error_of("1.5"), "doc.json:1:1: expected an integer, found number 1.5");
  EXPECT_EQ(integer_error_of("1e3"), "doc.json:1:1: expected an integer, found number 1e3");
  EXPECT_EQ(integer_error_of("2.0"), "doc.json:1:1: expected an integer, found number 2.0");
}

TEST(JsonPullNumbers, ConversionsCheckTheTokenType) {
  JsonPull json(R"( ["7", true, 3])", "doc.json");
  json.next();
  json.next();
  EXPECT_THROW(json.number(), JsonError);
  EXPECT_THROW(json.integer(), JsonError);
  EXPECT_THROW(json.boolean(), JsonError);
  try {
    json.number();
  } catch (const JsonError& e) {
    EXPECT_STREQ(e.what(), "doc.json:1:3: expected a number, found string \"7\"");
  }
  json.next();
  EXPECT_THROW(json.number(), JsonError);
  EXPECT_TRUE(json.boolean());
  json.next();
  EXPECT_THROW(json.boolean(), JsonError);
}

// number() takes a shortcut for short mantissas; it must agree bit for bit with
// std::from_chars, which rounds correctly, on numbers of every shape.
TEST(JsonPullNumbers, AgreesWithFromChars) {
  std::mt19937_64 random(20240611);
  for (int i = 0; i < 200000; ++i) {
    std::string text;
    if (random() % 2) text += '-';
    const int int_digits = 1 + static_cast<int>(random() % 12);
    const int fraction_digits = static_cast<int>(random() % 14);
    text += static_cast<char>('1' + random() % 9);
    for (int d = 1; d < int_digits; ++d) text += static_cast<char>('0' + random() % 10);
    if (random() % 5 == 0) text = text[0] == '-' ? "-0" : "0";
    if (fraction_digits > 0) {
      text += '.';
      for (int d = 0; d < fraction_digits; ++d) text += static_cast<char>('0' + random() % 10);
    }
    if (random() % 2) {
      text += random() % 2 ? 'e' : 'E';
      const int sign = static_cast<int>(random() % 3);
      if (sign == 1) text += '-';
      if (sign == 2) text += '+';
      text += std::to_string(random() % 40);
    }
    double expected = 0;
    std::from_chars(text.data(), text.data() + text.size(), expected);
    const double got = number_of(text);
    ASSERT_EQ(std::memcmp(&got, &expected, sizeof got), 0) << text << " gave " << got;
  }
}

// --- whole values ----------------------------------------------------------------------

TEST(JsonPullValues, SkipValue) {
  JsonPull json(R"({"skip":{"a":[1,{"b":2}],"c":"x"},"s":"scalar","keep":3,"arr":[[]],"n":null})",
                "doc.json");
  EXPECT_EQ(json.next(), Token::begin_object);
  EXPECT_EQ(json.next(), Token::key);
  json.skip_value();  // from the key: skips the object after it
  EXPECT_EQ(json.token(), Token::end_object);
  EXPECT_EQ(json.next(), Token::key);
  EXPECT_EQ(json.text(), "s");
  EXPECT_EQ(json.next(), Token::string);
  json.skip_value();  // a scalar is its own last token
  EXPECT_EQ(json.token(), Token::string);
  EXPECT_EQ(json.next(), Token::key);
  EXPECT_EQ(json.next(), Token::number);
  EXPECT_EQ(json.integer(), 3);
  EXPECT_EQ(json.next(), Token::key);
  EXPECT_EQ(json.next(), Token::begin_array);
  json.skip_value();  // from the value's first token
  EXPECT_EQ(json.token(), Token::end_array);
  EXPECT_EQ(json.next(), Token::key);
  json.skip_value();
  EXPECT_EQ(json.token(), Token::null);
  EXPECT_EQ(json.next(), Token::end_object);
  EXPECT_THROW(json.skip_value(), JsonError);  // a closing bracket starts no value
  EXPECT_EQ(json.next(), Token::end_of_input);
}

TEST(JsonPullValues, SkipValueStillChecksTheGrammar) {
  JsonPull json(R"({"skip":[1,2,,3]})", "doc.json");
  json.next();
  json.next();
  try {
    json.skip_value();
    FAIL() << "no error";
  } catch (const JsonError& e) {
    EXPECT_STREQ(e.what(), "doc.json:1:14: expected a value after ',', found ','");
  }
}

TEST(JsonPullValues, ReadValue) {
  JsonPull json(R"({"rules":{"name":"murray","exponent":3.0,"ids":[1,-2,18446744073709551615,
                  18446744073709551616,1e2],"on":true,"off":false,"none":null,"esc":"a\nb"},
                  "after":7})",
                "doc.json");
  EXPECT_EQ(json.next(), Token::begin_object);
  EXPECT_EQ(json.next(), Token::key);
  const nlohmann::json rules = json.read_value();
  EXPECT_EQ(json.token(), Token::end_object);
  EXPECT_EQ(rules["name"], "murray");
  EXPECT_TRUE(rules["exponent"].is_number_float());
  EXPECT_EQ(rules["exponent"], 3.0);
  const nlohmann::json& ids = rules["ids"];
  ASSERT_EQ(ids.size(), 5u);
  EXPECT_TRUE(ids[0].is_number_integer() && !ids[0].is_number_unsigned());
  EXPECT_EQ(ids[1].get<std::int64_t>(), -2);
  EXPECT_TRUE(ids[2].is_number_unsigned());
  EXPECT_EQ(ids[2].get<std::uint64_t>(), std::numeric_limits<std::uint64_t>::max());
  EXPECT_TRUE(ids[3].is_number_float());  // beyond 64 bits
  EXPECT_EQ(ids[3].get<double>(), 18446744073709551616.0);
  EXPECT_TRUE(ids[4].is_number_float());
  EXPECT_EQ(rules["on"], true);
  EXPECT_EQ(rules["off"], false);
  EXPECT_TRUE(rules["none"].is_null());
  EXPECT_EQ(rules["esc"], "a\nb");
  // The caller continues where the value ended.
  EXPECT_EQ(json.next(), Token::key);
  EXPECT_EQ(json.text(), "after");
  EXPECT_EQ(json.next(), Token::number);
  EXPECT_EQ(json.read_value(), 7);
  EXPECT_EQ(json.next(), Token::end_object);
  EXPECT_EQ(json.next(), Token::end_of_input);
}

TEST(JsonPullValues, ReadTopLevelValue) {
  JsonPull json(" [1, {\"a\": [ ]}, \"z\"] ", "doc.json");
  json.next();
  EXPECT_EQ(json.read_value(), nlohmann::json::parse(R"([1,{"a":[]},"z"])"));
  EXPECT_EQ(json.token(), Token::end_array);
  EXPECT_EQ(json.next(), Token::end_of_input);
}

TEST(JsonPullValues, RepeatedKeyKeepsTheLastValue) {
  const std::string text = R"({"a":1,"a":{"b":2}})";
  JsonPull json(text, "doc.json");
  json.next();
  EXPECT_EQ(json.read_value(), nlohmann::json::parse(text));
}

TEST(JsonPullValues, FailUsesTheTokenPosition) {
  JsonPull json("{\n  \"diameter\": -3\n}", "net.json");
  json.next();
  json.next();
  json.next();
  try {
    json.fail("diameter must be positive");
    FAIL() << "fail() returned";
  } catch (const JsonError& e) {
    EXPECT_STREQ(e.what(), "net.json:2:15: diameter must be positive");
  }
}

// --- input through a FILE* ---------------------------------------------------------------

// Tokens of every kind and escapes of every kind, for placing across chunk boundaries.
const std::string sample =
    R"({"k\u00e9y":"a\"b\\c\/d\b\f\n\r\t\u0041\ud83d\ude00)"
    "\xC3\xA9"
    R"(z","n":[-12.5e-3,0,1E+2,-0,123456789012345678901234567890,4015483],)"
    "\r\n\t "
    R"("t":true,"f":false,"z":null,"e":{},"a":[]})";

TEST(JsonPullStream, ChunkBoundaryInsideEveryToken) {
  // The boundary at 1 MiB falls, shift by shift, on every byte of the sample.
  for (std::size_t shift = 0; shift <= sample.size() + 1; ++shift) {
    const std::string padding(chunk - 4 - shift, 'x');
    const std::string text = "[\"" + padding + "\"," + sample + ",\n " + sample + "]";
    ASSERT_EQ(text.find(sample), chunk - shift);
    const auto expected = tokens_in_memory(text);
    const auto got = tokens_from_stream(text);
    ASSERT_EQ(got, expected) << "shift " << shift;
  }
}

TEST(JsonPullStream, ThreeMegabyteDocumentFromTmpfile) {
  // Long strings with escapes span whole chunks; numbers and keys of all lengths follow,
  // so many of them straddle the boundaries at 2 and 3 MiB.
  std::string text = "{\"long\":\"";
  for (int i = 0; text.size() < chunk + chunk / 2; ++i)
    text += i % 7 == 0 ? "\\n\\u00e9\\ud83d\\ude00" : "vessel segment ";
  text += "\",\"plain\":\"" + std::string(chunk + 17, 'p') + "\",\"numbers\":[";
  std::mt19937 random(7);
  for (int i = 0; text.size() < 3 * chunk + 1000; ++i) {
    if (i > 0) text += i % 10 == 0 ? ",\n" : ",";
    switch (i % 5) {
      case 0: text += std::to_string(random()); break;
      case 1: text += "-" + std::to_string(random() % 1000) + "." + std::to_string(random()); break;
      case 2: text += std::to_string(random() % 100) + "e-" + std::to_string(random() % 300); break;
      case 3: text += "{\"key_" + std::to_string(i) + "\":[true,false,null]}"; break;
      case 4: text += "\"s" + std::string(random() % 40, 'q') + "\""; break;
    }
  }
  text += "]}";

  std::FILE* file = std::tmpfile();
  ASSERT_NE(file, nullptr);
  ASSERT_EQ(std::fwrite(text.data(), 1, text.size(), file), text.size());
  std::rewind(file);
  JsonPull from_file(file, "doc.json");
  const auto got = all_tokens(from_file);
  std::fclose(file);
  const auto expected = tokens_in_memory(text);
  EXPECT_EQ(got.size(), expected.size());
  EXPECT_TRUE(got == expected);
  EXPECT_GT(got.size(), 50000u);

  // read_value from a stream builds the same document.
  file = std::tmpfile();
  ASSERT_EQ(std::fwrite(text.data(), 1, text.size(), file), text.size());
  std::rewind(file);
  JsonPull again(file, "doc.json");
  again.next();
  EXPECT_EQ(again.read_value(), nlohmann::json::parse(text));
  std::fclose(file);
}

TEST(JsonPullStream, ErrorsAtChunkBoundariesMatchMemory) {
  const std::string broken[] = {"[1,2,]", "[01]", "[1.e5]", "[\"a\\x\"]", "[\"\\ud800x\"]",
                                "[tru]", "[\"a\tb\"]"};
  for (const std::string& bad : broken) {
    for (std::size_t shift = 0; shift <= bad.size() + 1; ++shift) {
      const std::string text =
          "[\"" + std::string(chunk - 4 - shift, 'x') + "\"," + bad + "]";
      const std::string expected = error_of(text);
      ASSERT_NE(expected, "no error") << bad;
      ASSERT_EQ(stream_error_of(text), expected) << bad << " shift " << shift;
    }
  }
  // Cut off inside a string that spans a boundary: the position is the end of input.
  const std::string cut = "[\"" + std::string(chunk + 10, 'x');
  EXPECT_EQ(stream_error_of(cut),
            "doc.json:1:" + std::to_string(cut.size() + 1) + ": unexpected end of input inside string");
}

TEST(JsonPullStream, AnyBufferSizeGivesTheSameTokens) {
  const std::string text = std::string("{\"a\":") + sample + ",\"b\":[1,2,{\"c\":\"\\u00e9\"}]}";
  const auto expected = tokens_in_memory(text);
  for (std::size_t buffer = 0; buffer <= 70; ++buffer)  // 0 stands for 1
    ASSERT_EQ(tokens_from_stream(text, buffer), expected) << "buffer " << buffer;
}

TEST(JsonPullStream, EmptyStream) {
  EXPECT_EQ(stream_error_of(""), "doc.json:1:1: expected a value, found end of input");
  EXPECT_EQ(stream_error_of("\n\n"), "doc.json:3:1: expected a value, found end of input");
}

// --- malformed input -------------------------------------------------------------------

TEST(JsonPullErrors, ExactMessagesAndPositions) {
  struct Case { std::string text, error; };
  const Case cases[] = {
      // Commas, colons, keys.
      {"[1,2,]", "1:6: expected a value after ',', found ']'"},
      {R"({"a":1,})", "1:8: expected a string key after ',', found '}'"},
      {R"({"a" 1})", "1:6: expected ':' after object key, found '1'"},
      {R"({"a":1 "b":2})", "1:8: expected ',' or '}' after object member, found '\"'"},
      {"[1 2]", "1:4: expected ',' or ']' after array element, found '2'"},
      {"{1:2}", "1:2: expected a string key or '}', found '1'"},
      {"[,1]", "1:2: expected a value or ']', found ','"},
      // Brackets.
      {"[1}", "1:3: expected ',' or ']' after array element, found '}'"},
      {R"({"a":1])", "1:7: expected ',' or '}' after object member, found ']'"},
      {"[[1]", "1:5: expected ',' or ']' after array element, found end of input"},
      {"]", "1:1: expected a value, found ']'"},
      {"[1]]", "1:4: expected end of input after the top-level value, found ']'"},
      // More than one top-level value, or none.
      {"1 2", "1:3: expected end of input after the top-level value, found '2'"},
      {"{}\n{}", "2:1: expected end of input after the top-level value, found '{'"},
      {"", "1:1: expected a value, found end of input"},
      {"  \n   ", "2:4: expected a value, found end of input"},
      // Truncated input.
      {R"({"a":)", "1:6: expected a value after ':', found end of input"},
      {"[1,\n", "2:1: expected a value after ',', found end of input"},
      {R"({"a")", "1:5: expected ':' after object key, found end of input"},
      {"{", "1:2: expected a string key or '}', found end of input"},
      // Strings.
      {R"(["abc)", "1:6: unexpected end of input inside string"},
      {R"(["abc\)", "1:7: unexpected end of input inside string"},
      {R"(["\u12)", "1:7: unexpected end of input inside string"},
      {"[\"a\tb\"]", "1:4: unescaped control character 0x09 in string"},
      {"[\"a\nb\"]", "1:4: unescaped control character 0x0A in string"},
      {R"(["a\xb"])", "1:4: invalid escape '\\x' in string"},
      {R"(["\u12G4"])", "1:7: expected 4 hex digits after \\u, found 'G'"},
      {R"(["\ud800"])", "1:3: high surrogate in \\u escape not followed by a low surrogate"},
      {R"(["\ud800\u0041"])", "1:9: high surrogate in \\u escape not followed by a low surrogate"},
      {R"(["\udc00\ud800"])", "1:3: unpaired low surrogate in \\u escape"},
      // Literals.
      {"[tru]", "1:5: invalid literal, expected 'true', found ']'"},
      {"[nul", "1:5: unexpected end of input in literal, expected 'null'"},
      {"[falsy]", "1:6: invalid literal, expected 'false', found 'y'"},
      {"[True]", "1:2: expected a value or ']', found 'T'"},
      {"[truex]", "1:6: expected ',' or ']' after array element, found 'x'"},
      // Numbers.
      {"[01]", "1:2: leading zero in number"},
      {"-012", "1:2: leading zero in number"},
      {"[-]", "1:3: expected a digit after '-', found ']'"},
      {"[-a]", "1:3: expected a digit after '-', found 'a'"},
      {"[1.]", "1:4: expected a digit after the decimal point, found ']'"},
      {"[1.e3]", "1:4: expected a digit after the decimal point, found 'e'"},
      {"[1e]", "1:4: expected a digit in the exponent, found ']'"},
      {"[1e+]", "1:5: expected a digit in the exponent, found ']'"},
      {"1E", "1:3: expected a digit in the exponent, found end of input"},
      {"[1.5.2]", "1:5: unexpected '.' in number"},
      {"[1-2]", "1:3: unexpected '-' in number"},
      {"[.5]", "1:2: expected a value or ']', found '.'"},
      {"[+1]", "1:2: expected a value or ']', found '+'"},
      // Bytes that are not JSON at all.
      {"\xEF\xBB\xBF[]", "1:1: expected a value, found byte 0xEF"},
      {std::string("[\0]", 3), "1:2: expected a value or ']', found byte 0x00"},
      // A position on a later line.
      {"{\n  \"a\": [1,\n    2,,\n  ]\n}", "3:7: expected a value after ',', found ','"},
  };
  for (const Case& c : cases) EXPECT_EQ(error_of(c.text), "doc.json:" + c.error) << c.text;
}

// --- oracle: nlohmann::json ------------------------------------------------------------

// Random JSON text with every feature the grammar has, deterministic for a seed.
class RandomDocument {
 public:
  // raw_utf8: strings may hold multi-byte characters as such, not only as \u escapes.
  explicit RandomDocument(std::uint32_t seed, bool raw_utf8 = true)
      : random_(seed), pieces_(raw_utf8 ? std::size(pieces) : std::size(pieces) - 2) {}

  std::string make() {
    text_.clear();
    value(0);
    space();
    return text_;
  }

 private:
  std::uint32_t pick(std::uint32_t n) { return random_() % n; }

  void space() {
    static const char* const blanks[] = {"", "", "", " ", "\n", "\t", "\r\n", "  "};
    text_ += blanks[pick(8)];
  }

  static constexpr const char* pieces[] = {
      "a", "vessel", "_", " ", "\\\"", "\\\\", "\\/", "\\b", "\\f", "\\n", "\\r", "\\t",
      "\\u0041", "\\u00e9", "\\u20AC", "\\ud83d\\ude00", "\\u0000",
      "\xC3\xA9", "\xE2\x82\xAC"};  // raw UTF-8 last

  void string() {
    text_ += '"';
    for (std::uint32_t n = pick(8); n > 0; --n) text_ += pieces[pick(pieces_)];
    text_ += '"';
  }

  void number() {
    switch (pick(6)) {
      case 0: text_ += std::to_string(static_cast<std::int64_t>(random_()) - (1ll << 31)); break;
      case 1: text_ += std::to_string((static_cast<std::uint64_t>(random_()) << 32) | random_()); break;
      case 2: text_ += "-9223372036854775808"; break;
      case 3: text_ += "123456789012345678901234567890"; break;
      default: {
        if (pick(2)) text_ += '-';
        text_ += std::to_string(pick(1000)) + "." + std::to_string(random_());
        if (pick(2)) text_ += (pick(2) ? "e" : "E") + std::string(pick(2) ? "-" : "+") +
                              std::to_string(pick(300));
      }
    }
  }

  void value(int depth) {
    space();
    // Mostly containers at the top, scalars only deep down, so documents stay small.
    const std::uint32_t kind = depth == 0 && pick(4) > 0 ? pick(2)
                               : depth > 5               ? 2 + pick(5)
                                                         : pick(7);
    switch (kind) {
      case 0: {
        text_ += '{';
        const std::uint32_t n = pick(6);
        for (std::uint32_t i = 0; i < n; ++i) {
          if (i > 0) text_ += ',';
          space();
          string();
          space();
          text_ += ':';
          value(depth + 1);
        }
        if (n == 0) space();
        text_ += '}';
        break;
      }
      case 1: {
        text_ += '[';
        const std::uint32_t n = pick(6);
        for (std::uint32_t i = 0; i < n; ++i) {
          if (i > 0) text_ += ',';
          value(depth + 1);
        }
        if (n == 0) space();
        text_ += ']';
        break;
      }
      case 2: string(); break;
      case 3: case 4: number(); break;
      case 5: text_ += pick(2) ? "true" : "false"; break;
      case 6: text_ += "null"; break;
    }
    space();
  }

  std::mt19937 random_;
  std::uint32_t pieces_;  // how many of pieces to draw from
  std::string text_;
};

TEST(JsonPullOracle, ReadValueMatchesNlohmann) {
  RandomDocument documents(12345);
  for (int i = 0; i < 2000; ++i) {
    const std::string text = documents.make();
    const nlohmann::json expected = nlohmann::json::parse(text);
    JsonPull json(text, "doc.json");
    json.next();
    ASSERT_EQ(json.read_value(), expected) << text;
    ASSERT_EQ(json.next(), Token::end_of_input) << text;

    JsonPull skipping(text, "doc.json");
    skipping.next();
    skipping.skip_value();
    ASSERT_EQ(skipping.next(), Token::end_of_input) << text;
  }
}

TEST(JsonPullOracle, ReadValueFromStreamMatchesNlohmann) {
  // One big array of random documents, so values straddle chunk boundaries.
  RandomDocument documents(777);
  std::string text = "[";
  while (text.size() < 3 * chunk) {
    if (text.size() > 1) text += ',';
    text += documents.make();
  }
  text += ']';
  std::FILE* in = fmemopen(text.data(), text.size(), "r");
  ASSERT_NE(in, nullptr);
  JsonPull json(in, "doc.json");
  json.next();
  EXPECT_EQ(json.read_value(), nlohmann::json::parse(text));
  EXPECT_EQ(json.next(), Token::end_of_input);
  std::fclose(in);
}

// The error of building the whole document, as nlohmann::json::parse does.
std::string read_error_of(std::string_view text) {
  try {
    JsonPull json(text, "doc.json");
    json.next();
    json.read_value();
    json.next();
  } catch (const JsonError& e) {
    return e.what();
  }
  return "no error";
}

// Damaged copies of valid documents: we reject exactly what nlohmann rejects. (Raw UTF-8
// stays out: a damaged multi-byte character is an error to nlohmann, not to us.)
TEST(JsonPullOracle, RejectsWhatNlohmannRejects) {
  RandomDocument documents(99, false);
  std::mt19937 random(5);
  const char damage[] = {',', ':', '[', ']', '{', '}', '"', '\\', '0', '-', '.', 'e', 'x', ' '};
  int rejected = 0;
  for (int i = 0; i < 3000; ++i) {
    std::string text = documents.make();
    if (text.empty()) continue;
    const std::size_t at = random() % text.size();
    switch (random() % 3) {
      case 0: text[at] = damage[random() % sizeof damage]; break;
      case 1: text.erase(at, 1); break;
      case 2: text.insert(text.begin() + static_cast<std::ptrdiff_t>(at), damage[random() % sizeof damage]); break;
    }
    const bool nlohmann_accepts = nlohmann::json::accept(text);
    const std::string error = read_error_of(text);
    if (!nlohmann_accepts) ++rejected;
    EXPECT_EQ(error == "no error", nlohmann_accepts) << text << "\n" << error;
  }
  EXPECT_GT(rejected, 1000);
}

}  // namespace
