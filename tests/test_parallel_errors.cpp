// core/parallel_errors.hpp: an exception thrown in an OpenMP loop reaches the caller, the one
// of the lowest index whatever the threads (an escaping one would call std::terminate).
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "core/parallel_errors.hpp"

using namespace hemotree;

namespace {
std::string run_loop(int threads, std::initializer_list<int> failing) {
  ParallelErrors errors;
  std::int64_t done = 0;
#pragma omp parallel for schedule(static) num_threads(threads) reduction(+ : done)
  for (std::int64_t i = 0; i < 1000; ++i) {
    errors.guard(i, [&] {
      for (const int f : failing)
        if (i == f) throw std::runtime_error("index " + std::to_string(i));
      ++done;
    });
  }
  EXPECT_EQ(done, 1000 - static_cast<std::int64_t>(failing.size()));  // the others all ran
  try {
    errors.rethrow();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(ParallelErrors, TheLowestIndexReachesTheCallerForAnyThreadCount) {
  for (const int threads : {1, 2, 4}) {
    EXPECT_EQ(run_loop(threads, {900, 17, 503}), "index 17") << threads << " threads";
    EXPECT_EQ(run_loop(threads, {}), "") << threads << " threads";
  }
}

TEST(ParallelErrors, RethrowsOnceThenIsClear) {
  ParallelErrors errors;
  errors.guard(3, [] { throw std::runtime_error("x"); });
  EXPECT_THROW(errors.rethrow(), std::runtime_error);
  EXPECT_NO_THROW(errors.rethrow());
}
