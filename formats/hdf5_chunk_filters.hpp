// A column's chunk through the filters hemotree sets on every HDF5 column, here rather than in
// the library so that the chunks of a column are filtered on every thread (deflate runs at
// about 100 MB/s a thread) and handed to the library as it would have stored them
// (H5Dwrite_chunk). The same bytes as HDF5 1.10's own filters: the library reads them back
// through its filters (tests/test_network_hdf5.cpp), and the full tree's network file was the
// same bytes either way.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace hemotree::hdf5 {

// HDF5's Fletcher-32 (H5_checksum_fletcher32): 16-bit words, most significant byte first, the
// sums folded every 360 words; an odd last byte as a word's high byte.
std::uint32_t fletcher32(const unsigned char* data, std::size_t length);

// The filters in their order: the byte shuffle (byte k of every element together), deflate
// (zlib's compress2 at deflate_level) and the Fletcher-32 of the result appended in the
// machine's order. values: the chunk's rows (element bytes each); a last chunk is padded with
// zeros, the fill value, to the chunk's rows, as the library stores it. std::bad_alloc where
// zlib has no memory.
std::vector<unsigned char> filtered_chunk(const unsigned char* values, std::size_t rows, std::size_t chunk,
                                          std::size_t element, int deflate_level);

}  // namespace hemotree::hdf5
