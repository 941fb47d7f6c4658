// This machine's memory bandwidth, as STREAM (McCalpin 1995) measures it: the four kernels
// copy a = b, scale a = s b, add a = b + c and triad a = b + s c over arrays far larger than
// the caches, with 1 and then 2 threads (OpenMP, static schedule, each thread first touching
// the part it works on). Bytes are counted as STREAM counts them: 16 per element for copy and
// scale, 24 for add and triad (the write-allocate read of `a` not counted), so the figures are
// comparable with published STREAM results. The best of the repetitions is quoted (STREAM's
// rule: the machine's capability, not its noise), and the median beside it.
// usage: memory_bandwidth [MILLION_ELEMENTS (80)] [REPEATS (10)]
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

namespace {

struct Figure {
  double best = 0, median = 0;  // [GB/s]
};

template <class Kernel>
Figure measure(long n, int threads, int repeats, double bytes_per_element, Kernel&& kernel) {
  std::vector<double> rates;
  for (int r = 0; r < repeats; ++r) {
    const auto start = std::chrono::steady_clock::now();
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long i = 0; i < n; ++i) kernel(i);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    rates.push_back(bytes_per_element * static_cast<double>(n) / seconds / 1e9);
  }
  std::sort(rates.begin(), rates.end());
  return {rates.back(), rates[rates.size() / 2]};
}

}  // namespace

int main(int argc, char** argv) {
  const long n = (argc > 1 ? std::atol(argv[1]) : 80) * 1000000L;
  const int repeats = argc > 2 ? std::atoi(argv[2]) : 10;
  if (n <= 0 || repeats <= 0) {
    std::fprintf(stderr, "usage: memory_bandwidth [MILLION_ELEMENTS > 0] [REPEATS > 0]\n");
    return 2;
  }
  // Uninitialised storage, first touched in parallel below (each thread's pages on its node).
  std::unique_ptr<double[]> a(new double[static_cast<std::size_t>(n)]), b(new double[static_cast<std::size_t>(n)]),
      c(new double[static_cast<std::size_t>(n)]);
  const int max_threads = omp_get_num_procs();
#pragma omp parallel for schedule(static) num_threads(max_threads)
  for (long i = 0; i < n; ++i) {
    a[i] = 1.0;
    b[i] = 2.0;
    c[i] = 0.0;
  }
  std::printf("arrays of %ld doubles (%.2f GB each), best and median of %d\n", n, 8.0 * static_cast<double>(n) / 1e9,
              repeats);
  std::printf("%-7s %8s %12s %12s\n", "kernel", "threads", "best GB/s", "median GB/s");
  const double s = 3.0;
  for (int threads = 1; threads <= max_threads; ++threads) {
    const Figure figures[] = {
        measure(n, threads, repeats, 16, [&](long i) { c[i] = a[i]; }),
        measure(n, threads, repeats, 16, [&](long i) { b[i] = s * c[i]; }),
        measure(n, threads, repeats, 24, [&](long i) { c[i] = a[i] + b[i]; }),
        measure(n, threads, repeats, 24, [&](long i) { a[i] = b[i] + s * c[i]; }),
    };
    const char* names[] = {"copy", "scale", "add", "triad"};
    for (int k = 0; k < 4; ++k)
      std::printf("%-7s %8d %12.2f %12.2f\n", names[k], threads, figures[k].best, figures[k].median);
  }
  // Keeps the kernels' results live.
  double check = 0;
  for (long i = 0; i < n; i += 4096) check += a[i] + b[i] + c[i];
  return check == 0 ? 1 : 0;
}
