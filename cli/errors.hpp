// Errors a user can act on. Every tool catches them in main and prints one line.
#pragma once

#include <stdexcept>
#include <string>

namespace hemotree {

// Bad input: a flag, a value, a file's content. Exit status 2.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The environment failed us: cannot open, read or write a file. Exit status 1.
struct IoError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace hemotree
