// Reading and writing the vnet format (docs/network-format.md): JSON, streamed both ways (a
// tree of millions of vessels goes through a pipe without a document tree in memory), and
// the same content as HDF5 columns. Readers tell the two apart by their first byte.
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

namespace hdf5 {
class File;
}
struct NetworkSlice;

// path "-" reads standard input; either form (an HDF5 file by its signature). Throws InputError naming the position or the vessel at
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

// The HDF5 form (formats/network_hdf5.cpp), written through out (hdf5::write_through: at its
// temporary, renamed by its commit), so that it is as atomic as the JSON one and may go to a pipe.
void write_network_hdf5(const Network& net, OutputStream& out);
// Throws InputError naming the file, the dataset and the row at fault.
Network read_network_hdf5(const hdf5::File& file);
// Its topology and a slice of it (formats/network_slice.hpp, which reads them from a path).
Network read_network_topology_hdf5(const hdf5::File& file);
NetworkSlice read_network_slice_hdf5(const hdf5::File& file, const Network& topology,
                                     std::span<const std::int32_t> vessels);

}  // namespace hemotree
