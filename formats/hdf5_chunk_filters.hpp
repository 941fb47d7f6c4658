// A column's chunk through the filters hemotree sets on every HDF5 column, here rather than in
// the library so that the chunks of a column are filtered on every thread (deflate runs at
// about 100 MB/s a thread) and handed to the library as it would have stored them
// (H5Dwrite_chunk). The library reads them back through its own filters
// (tests/test_network_hdf5.cpp); with zlib's default strategy they are the library's own
// bytes (the full tree's network file was the same either way).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

namespace hemotree::hdf5 {

// HDF5's Fletcher-32 (H5_checksum_fletcher32): 16-bit words, most significant byte first, the
// sums folded every 360 words; an odd last byte as a word's high byte.
std::uint32_t fletcher32(const unsigned char* data, std::size_t length);

// The filters in their order: the byte shuffle (byte k of every element together), deflate
// (zlib at deflate_level) and the Fletcher-32 of the result appended in the machine's order.
// `strategy` is zlib's (Z_DEFAULT_STRATEGY, as the library's own filter deflates, or Z_RLE):
// any deflate stream is what the library's filter inflates. One a thread: zlib's state and
// the chunk's buffers are kept from one chunk to the next (made afresh, they were about
// 1.3 MB of fresh pages a chunk). std::bad_alloc where zlib has no memory.
class ChunkFilter {
 public:
  // chunk: the rows of a whole chunk; element: the bytes of a value.
  ChunkFilter(std::size_t chunk, std::size_t element, int deflate_level, int strategy);
  ~ChunkFilter();
  ChunkFilter(const ChunkFilter&) = delete;
  ChunkFilter& operator=(const ChunkFilter&) = delete;
  // values: the chunk's rows (at most chunk); a last chunk is padded with zeros, the fill
  // value, to the chunk's rows, as the library stores it.
  std::vector<unsigned char> operator()(const unsigned char* values, std::size_t rows);

 private:
  struct Deflate;
  std::size_t chunk_, element_;
  std::unique_ptr<Deflate> deflate_;
  std::vector<unsigned char> shuffled_, packed_;
};

}  // namespace hemotree::hdf5
