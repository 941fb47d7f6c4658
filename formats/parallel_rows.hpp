// Rows of text formatted in parallel and written in their order. A row's text depends on the
// row alone, so the bytes are the same for any number of threads. Writing a table of millions
// of rows is formatting numbers (std::to_chars: summary.json and vessels.csv of the full tree
// are 3.5 GB) and the kernel's copy of the text into the page cache: blocks of rows are
// formatted by every thread into a ring of buffers while one of them writes the blocks out
// in order (formatting too when the next block is not ready).
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <omp.h>

#include "formats/output_stream.hpp"

namespace hemotree {

// append_row(text, row) appends row's text to text; between rows, `separator`. Rows 0 .. rows - 1.
template <class AppendRow>
void write_rows(OutputStream& out, std::size_t rows, int threads, std::string_view separator,
                const AppendRow& append_row) {
  constexpr std::size_t block_rows = 4096;  // a few hundred kB of text
  const std::size_t blocks = (rows + block_rows - 1) / block_rows;
  // Into a string of the formatting thread's own (its buffer moved in and out of the slot):
  // the slots' string objects lie side by side, and every append writes a length, so appending
  // to them in place made two threads as slow as one (each line of cache passed back and forth).
  auto format = [&](std::size_t block, std::string& slot_text) {
    std::string text = std::move(slot_text);
    text.clear();
    const std::size_t first = block * block_rows, last = std::min(rows, first + block_rows);
    for (std::size_t row = first; row < last; ++row) {
      if (row > 0) text += separator;
      append_row(text, row);
    }
    slot_text = std::move(text);
  };
  if (threads <= 1 || blocks <= 1) {
    std::string text;
    for (std::size_t block = 0; block < blocks; ++block) {
      format(block, text);
      out << text;
    }
    return;
  }
  // Block b is formatted into slot b % ring once block b - ring is written; the writer
  // (thread 0) writes block w once its slot holds it.
  const std::size_t ring = 2 * static_cast<std::size_t>(threads);
  std::vector<std::string> slot(ring);
  std::vector<std::atomic<std::size_t>> holds(ring);  // the block + 1 a slot holds, 0: none yet
  for (auto& h : holds) h.store(0);
  std::atomic<std::size_t> next{0}, written{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;  // the first failure: a write's (IoError) or a format's (bad_alloc)
  auto fail = [&] {
#pragma omp critical(hemotree_write_rows)
    if (!error) error = std::current_exception();
    failed.store(true);
  };
#pragma omp parallel num_threads(threads)
  {
    const bool writer = omp_get_thread_num() == 0;
    while (!failed.load(std::memory_order_relaxed)) {
      if (writer) {
        const std::size_t w = written.load(std::memory_order_relaxed);
        if (w == blocks) break;
        if (holds[w % ring].load(std::memory_order_acquire) == w + 1) {
          try {
            out << slot[w % ring];
          } catch (...) {
            fail();
            break;
          }
          written.store(w + 1, std::memory_order_release);
          continue;
        }
      }
      std::size_t b = next.load(std::memory_order_relaxed);
      if (b >= blocks) {
        if (!writer) break;
        std::this_thread::yield();  // the writer waits for the last blocks
        continue;
      }
      if (b >= written.load(std::memory_order_acquire) + ring) {  // the ring is full
        std::this_thread::yield();
        continue;
      }
      if (!next.compare_exchange_weak(b, b + 1, std::memory_order_relaxed)) continue;
      try {
        format(b, slot[b % ring]);
      } catch (...) {
        fail();
        break;
      }
      holds[b % ring].store(b + 1, std::memory_order_release);
    }
  }
  if (error) std::rethrow_exception(error);
}

}  // namespace hemotree
