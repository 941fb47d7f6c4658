// Text from outside (ids, tracer names, file names) quoted for the formats the tools write,
// so that any string a user can give leaves the file parseable: a JSON string (RFC 8259:
// control characters escaped, bytes that are not UTF-8 replaced by U+FFFD) and a CSV field
// (RFC 4180: quoted when it holds a comma, a quote or a line break; quotes doubled).
#pragma once

#include <string>
#include <string_view>

namespace hemotree {

// "text" with its quotes, as a JSON string.
std::string json_quoted(std::string_view text);

// text as one CSV field: unchanged when nothing in it needs quoting.
std::string csv_field(std::string_view text);

// text for an error message, which is one line: control and non-ASCII bytes shown as \xNN.
std::string printable(std::string_view text);

}  // namespace hemotree
