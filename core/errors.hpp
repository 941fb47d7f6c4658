// Errors a user can act on, raised by any layer (formats up to the tools) and caught by each
// tool's run_tool (cli/tool.hpp), which prints one line. In the core room, below every layer:
// a reader or a law must not include a command-line header to refuse a value.
#pragma once

#include <stdexcept>
#include <string>

namespace hemotree {

// Bad input: a flag, a value, a file's content. Exit status 2.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Malformed or unexpected JSON (formats/json_pull.hpp); what() is
// "<source>:<line>:<column>: <message>". Exit status 2.
struct JsonError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The environment failed us: cannot open, read or write a file. Exit status 1.
struct IoError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace hemotree
