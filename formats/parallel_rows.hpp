// Rows of text formatted in parallel and written in their order. A row's text depends on the
// row alone, so the bytes are the same for any number of threads. Writing a table of millions
// of rows is mostly formatting numbers (std::to_chars: summary.json and vessels.csv of the
// full tree are 3.5 GB): blocks of rows are formatted by the threads at once, then written
// one after another.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/parallel_errors.hpp"
#include "formats/output_stream.hpp"

namespace hemotree {

// append_row(text, row) appends row's text to text; between rows, `separator`. Rows 0 .. rows - 1.
template <class AppendRow>
void write_rows(OutputStream& out, std::size_t rows, int threads, std::string_view separator,
                const AppendRow& append_row) {
  constexpr std::size_t block_rows = 4096;  // a few hundred kB of text
  const std::size_t blocks = (rows + block_rows - 1) / block_rows;
  const auto round = static_cast<std::size_t>(threads > 1 ? threads : 1);
  std::vector<std::string> text(round);
  for (std::size_t first_block = 0; first_block < blocks; first_block += round) {
    const std::size_t count = std::min(round, blocks - first_block);
    parallel_blocks(static_cast<std::int64_t>(count), threads, [&](std::int64_t begin, std::int64_t end) {
      for (auto j = static_cast<std::size_t>(begin); j < static_cast<std::size_t>(end); ++j) {
        std::string& t = text[j];
        t.clear();
        const std::size_t first = (first_block + j) * block_rows, last = std::min(rows, first + block_rows);
        for (std::size_t row = first; row < last; ++row) {
          if (row > 0) t += separator;
          append_row(t, row);
        }
      }
    });
    for (std::size_t j = 0; j < count; ++j) out << text[j];
  }
}

}  // namespace hemotree
