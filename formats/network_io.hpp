// Reading and writing the vnet JSON format (docs/network-format.md), streaming both ways:
// a tree of millions of vessels goes through a pipe without a document tree in memory.
#pragma once

#include <cstdio>
#include <string>
#include <string_view>

#include "formats/network.hpp"
#include "formats/output_stream.hpp"

namespace hemotree {

inline constexpr int vnet_version = 1;

// path "-" reads standard input. Throws InputError naming the position or the vessel at
// fault, IoError when the file cannot be read.
Network read_network(const std::string& path);
Network read_network(std::FILE* in, const std::string& source);
Network parse_network(std::string_view text, const std::string& source = "<text>");

void write_network(const Network& net, OutputStream& out);

}  // namespace hemotree
