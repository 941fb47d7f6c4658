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

std::vector<unsigned char> filtered_chunk(const unsigned char* values, std::size_t rows, std::size_t chunk,
                                          std::size_t element, int deflate_level) {
  const std::size_t bytes = chunk * element;
  std::vector<unsigned char> shuffled(bytes, 0);
  if (element == 1) {
    std::memcpy(shuffled.data(), values, rows);
  } else {
    for (std::size_t i = 0; i < rows; ++i)
      for (std::size_t k = 0; k < element; ++k) shuffled[k * chunk + i] = values[i * element + k];
  }
  uLongf packed = compressBound(bytes);
  std::vector<unsigned char> out(packed + 4);
  if (compress2(out.data(), &packed, shuffled.data(), bytes, deflate_level) != Z_OK)
    throw std::bad_alloc();  // compress2 fails only for want of memory with a bound-sized buffer
  const std::uint32_t sum = fletcher32(out.data(), packed);
  std::memcpy(out.data() + packed, &sum, 4);
  out.resize(packed + 4);
  return out;
}

}  // namespace hemotree::hdf5
