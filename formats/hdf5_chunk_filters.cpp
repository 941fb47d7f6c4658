#include "formats/hdf5_chunk_filters.hpp"

#include <algorithm>
#include <cstring>
#include <new>

#include <zlib.h>

namespace hemotree::hdf5 {

std::uint32_t fletcher32(const unsigned char* data, std::size_t length) {
  std::uint32_t sum1 = 0, sum2 = 0;
  for (std::size_t words = length / 2; words > 0;) {
    std::size_t block = std::min<std::size_t>(words, 360);
    words -= block;
    for (; block > 0; --block, data += 2) {
      sum1 += static_cast<std::uint32_t>(data[0]) << 8 | data[1];
      sum2 += sum1;
    }
    sum1 = (sum1 & 0xffff) + (sum1 >> 16);
    sum2 = (sum2 & 0xffff) + (sum2 >> 16);
  }
  if (length % 2 != 0) {
    sum1 += static_cast<std::uint32_t>(*data) << 8;
    sum2 += sum1;
    sum1 = (sum1 & 0xffff) + (sum1 >> 16);
    sum2 = (sum2 & 0xffff) + (sum2 >> 16);
  }
  sum1 = (sum1 & 0xffff) + (sum1 >> 16);
  sum2 = (sum2 & 0xffff) + (sum2 >> 16);
  return sum2 << 16 | sum1;
}

struct ChunkFilter::Deflate {
  z_stream stream{};
};

ChunkFilter::ChunkFilter(std::size_t chunk, std::size_t element, int deflate_level, int strategy)
    : chunk_(chunk), element_(element), deflate_(std::make_unique<Deflate>()), shuffled_(chunk * element, 0) {
  // compress2's window and memory level (with the default strategy, the library's bytes).
  if (deflateInit2(&deflate_->stream, deflate_level, Z_DEFLATED, MAX_WBITS, 8, strategy) != Z_OK) throw std::bad_alloc();
  packed_.resize(deflateBound(&deflate_->stream, static_cast<uLong>(shuffled_.size())) + 4);
}

ChunkFilter::~ChunkFilter() { deflateEnd(&deflate_->stream); }

std::vector<unsigned char> ChunkFilter::operator()(const unsigned char* values, std::size_t rows) {
  const std::size_t bytes = shuffled_.size();
  if (element_ == 1) {
    std::memcpy(shuffled_.data(), values, rows);
  } else {
    for (std::size_t i = 0; i < rows; ++i)
      for (std::size_t k = 0; k < element_; ++k) shuffled_[k * chunk_ + i] = values[i * element_ + k];
  }
  if (rows < chunk_)  // the padding; the bytes of a row beyond may hold the last chunk's
    for (std::size_t k = 0; k < element_; ++k) std::memset(shuffled_.data() + k * chunk_ + rows, 0, chunk_ - rows);
  z_stream& z = deflate_->stream;
  if (deflateReset(&z) != Z_OK) throw std::bad_alloc();
  z.next_in = shuffled_.data();
  z.avail_in = static_cast<uInt>(bytes);
  z.next_out = packed_.data();
  z.avail_out = static_cast<uInt>(packed_.size() - 4);
  // The bound's buffer takes the whole stream in one call (compress2's).
  if (deflate(&z, Z_FINISH) != Z_STREAM_END) throw std::bad_alloc();
  const std::size_t packed = z.total_out;
  const std::uint32_t sum = fletcher32(packed_.data(), packed);
  std::memcpy(packed_.data() + packed, &sum, 4);
  return {packed_.begin(), packed_.begin() + static_cast<std::ptrdiff_t>(packed + 4)};
}

}  // namespace hemotree::hdf5
