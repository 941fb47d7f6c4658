// The bytes arrays hold (their capacity, not their size): what a component says it holds, so
// that its memory a vessel can be read and pinned (docs/transport.md, "Memory").
#pragma once

#include <cstddef>
#include <vector>

namespace hemotree {

template <class T>
std::size_t array_bytes(const std::vector<T>& array) {
  return array.capacity() * sizeof(T);
}

template <class... Arrays>
std::size_t arrays_bytes(const Arrays&... arrays) {
  return (std::size_t{0} + ... + array_bytes(arrays));
}

}  // namespace hemotree
