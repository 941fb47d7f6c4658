// An exception thrown inside an OpenMP region cannot leave it: the runtime calls
// std::terminate, and the tool dies with "terminate called ..." instead of its one line
// (hostile-inputs 00: the Pries law's refusal of a NaN lumen, thrown in a parallel loop).
// Each iteration that may throw runs through guard(); the region's caller calls rethrow()
// after it. Of several failing iterations the lowest index wins, so the message is the same
// for any number of threads.
#pragma once

#include <cstdint>
#include <exception>
#include <limits>
#include <utility>

#include <omp.h>

namespace hemotree {

class ParallelErrors {
 public:
  // Runs body(); an exception it throws is kept (the one of the lowest index), not propagated.
  template <class Body>
  void guard(std::int64_t index, Body&& body) noexcept {
    try {
      body();
    } catch (...) {
#pragma omp critical(hemotree_parallel_errors)
      if (index < index_) {
        index_ = index;
        error_ = std::current_exception();
      }
    }
  }

  // Outside the region: throws the kept exception, if any.
  void rethrow() {
    if (!error_) return;
    index_ = std::numeric_limits<std::int64_t>::max();
    std::rethrow_exception(std::exchange(error_, nullptr));
  }

 private:
  std::int64_t index_ = std::numeric_limits<std::int64_t>::max();
  std::exception_ptr error_;
};

// body(first, last) over [0, count) in contiguous blocks, one per thread (the split of
// schedule(static)), each under one guard: the loop inside a block stays a plain loop, as fast
// as unguarded (a guard per iteration cost 6 % in the 0D vessels' assembly). The exception
// of the lowest block wins, within it the first thrown: the lowest index, for any threads.
template <class Body>
void parallel_blocks(std::int64_t count, int threads, Body&& body) {
  ParallelErrors errors;
#pragma omp parallel num_threads(threads) if (threads > 1)
  {
    const std::int64_t parts = omp_get_num_threads(), me = omp_get_thread_num();
    const std::int64_t first = count * me / parts, last = count * (me + 1) / parts;
    errors.guard(first, [&] { body(first, last); });
  }
  errors.rethrow();
}

}  // namespace hemotree
