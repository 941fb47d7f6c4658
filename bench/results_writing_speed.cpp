// Speed of writing a run's per-vessel results (formats/parallel_rows.hpp): a table of N rows
// shaped as a pulsatile run's (an id, a class label, 18 numbers spread over 30 decades), its
// rows as vessels.csv and as summary.json's vessel objects, with 1 and 2 threads, to
// /dev/null (formatting alone) and to a file in FOLDER (removed before each write, as a new
// run's file is new: the kernel's page cache is fresh memory then). Medians of 3, the
// configurations alternated.
// usage: results_writing_speed [N (3800000)] [FOLDER (/tmp)]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "formats/output_stream.hpp"
#include "formats/parallel_rows.hpp"
#include "solver/run_report.hpp"
#include "solver/vessel_table.hpp"

using namespace hemotree;

int main(int argc, char** argv) {
  const std::size_t n = argc > 1 ? std::strtoull(argv[1], nullptr, 10) : 3800000;
  const std::filesystem::path folder = argc > 2 ? argv[2] : "/tmp";
  VesselTable table(n);
  std::vector<std::int64_t> id(n);
  for (std::size_t i = 0; i < n; ++i) id[i] = static_cast<std::int64_t>(i);
  table.add_integer("id", std::move(id));
  table.add_text("class", std::vector<std::uint8_t>(n, 1), {"artery", "capillary"});
  std::mt19937_64 random(1);
  std::uniform_real_distribution<double> decades(-15, 15);
  for (int c = 0; c < 18; ++c) {
    std::vector<double> x(n);
    for (double& v : x) v = std::pow(10.0, decades(random));
    table.add_number("quantity_" + std::to_string(c), std::move(x));
  }
  const std::filesystem::path file = folder / ("results_writing_speed." + std::to_string(::getpid()));
  std::map<std::string, std::vector<double>> seconds;
  for (int repeat = 0; repeat < 3; ++repeat)
    for (const char* format : {"csv", "json"})
      for (const int threads : {1, 2})
        for (const bool to_file : {false, true}) {
          std::filesystem::remove(file);
          const auto start = std::chrono::steady_clock::now();
          if (std::string(format) == "csv") {
            write_vessel_table(to_file ? file : "/dev/null", table, threads);
          } else {
            OutputStream out(to_file ? file.string() : "/dev/null");
            write_rows(out, n, threads, ",\n  ", [&](std::string& text, std::size_t v) { table.append_json_row(text, v); });
            out.commit();
          }
          const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
          seconds[std::string(format) + ", " + std::to_string(threads) + " thread(s), " + (to_file ? "a file" : "/dev/null")]
              .push_back(s);
        }
  std::filesystem::remove(file);
  std::printf("%zu rows, median of 3 (s):\n", n);
  for (auto& [what, s] : seconds) {
    std::sort(s.begin(), s.end());
    std::printf("  %-32s %.2f   (%.2f .. %.2f)\n", what.c_str(), s[1], s.front(), s.back());
  }
}
