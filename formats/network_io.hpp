// Reading and writing the vnet JSON format (docs/network-format.md), streaming both ways:
// a tree of millions of vessels goes through a pipe without a document tree in memory.
#pragma once

#include <cstddef>
#include <cstdio>
#include <string>
#include <string_view>

#include "formats/network.hpp"
#include "formats/output_stream.hpp"

namespace hemotree {

// The newest version this build reads; writers write the oldest that holds the content
// (version 2: node boundaries, tapered vessels).
inline constexpr int vnet_version = 2;
int format_version_needed(const Network& net);

// path "-" reads standard input. Throws InputError naming the position or the vessel at
// fault, IoError when the file cannot be read.
Network read_network(const std::string& path);
Network read_network(std::FILE* in, const std::string& source);
// The same through a read buffer of buffer_bytes (default JsonPull::buffer_size, 1 MiB):
// a tiny buffer puts a refill inside every token, so tests and fuzzers can check that
// streamed and in-memory reading agree byte for byte.
Network read_network(std::FILE* in, const std::string& source, std::size_t buffer_bytes);
// Reads a network held in memory (the text must stay alive during the call only).
Network parse_network(std::string_view text, const std::string& source = "<text>");

void write_network(const Network& net, OutputStream& out);

}  // namespace hemotree
