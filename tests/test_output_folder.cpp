// hemosolve's output folder: a run writes into OUT.partial, which replaces OUT whole; a
// folder of other files is never replaced; a live writer's staging folder is never taken.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include <gtest/gtest.h>
#include <unistd.h>

#include "cli/errors.hpp"
#include "solver/output_folder.hpp"
#include "solver/run_estimate.hpp"

namespace hemotree {
namespace {

namespace fs = std::filesystem;

struct Scratch {
  fs::path dir = fs::temp_directory_path() / ("output-folder-test-" + std::to_string(::getpid()));
  Scratch() { fs::create_directories(dir); }
  ~Scratch() { fs::remove_all(dir); }
};

void write(const fs::path& file, const std::string& text) { std::ofstream(file) << text; }
std::string read(const fs::path& file) {
  std::ifstream in(file);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(OutputFolder, NewResultsReplaceTheOldWhole) {
  Scratch s;
  const fs::path out = s.dir / "run";
  {
    OutputFolder first(out);
    first.open();
    write(first.staging() / "summary.json", "one");
    write(first.staging() / "probes.csv", "old probes");
    first.publish();
  }
  EXPECT_EQ(read(out / "summary.json"), "one");
  OutputFolder second(out / "");  // "run/" names the same folder
  EXPECT_EQ(second.final_path(), out);
  second.open();
  EXPECT_EQ(second.staging(), fs::path(out.string() + ".partial"));
  // Until it is published, the previous results are untouched.
  write(second.staging() / "summary.json", "two");
  EXPECT_EQ(read(out / "summary.json"), "one");
  second.publish();
  EXPECT_EQ(read(out / "summary.json"), "two");
  EXPECT_FALSE(fs::exists(out / "probes.csv"));  // nothing of the previous run stays
  EXPECT_FALSE(fs::exists(second.staging()));
  EXPECT_FALSE(fs::exists(out / ".hemosolve-owner"));
}

TEST(OutputFolder, RefusesAFolderOfOtherFiles) {
  Scratch s;
  write(s.dir / "notes.txt", "mine");
  EXPECT_THROW(OutputFolder{s.dir}, InputError);
  EXPECT_EQ(read(s.dir / "notes.txt"), "mine");
}

TEST(OutputFolder, RefusesALiveWriterAndTakesOverADeadOne) {
  Scratch s;
  const fs::path out = s.dir / "run", staging = out.string() + ".partial";
  fs::create_directories(staging);
  write(staging / ".hemosolve-owner", std::to_string(::getpid()) + "\n");  // alive: this process
  EXPECT_THROW(OutputFolder{out}, InputError);
  // A process id that no process has (above the kernel's pid_max).
  write(staging / ".hemosolve-owner", "2147483647\n");
  write(staging / "checkpoint.bin", "x");
  OutputFolder f(out);
  ASSERT_TRUE(f.latest_checkpoint());
  EXPECT_EQ(*f.latest_checkpoint(), staging / "checkpoint.bin");
  f.open();  // the dead run's folder goes
  EXPECT_FALSE(fs::exists(staging / "checkpoint.bin"));
  f.discard();
  EXPECT_FALSE(fs::exists(staging));
  EXPECT_FALSE(fs::exists(out));
}

TEST(RunEstimate, DurationsReadAsPeopleSayThem) {
  EXPECT_EQ(describe_duration(3.2), "3.2 s");
  EXPECT_EQ(describe_duration(300), "5 min");
  EXPECT_EQ(describe_duration(3 * 3600), "3 h");
  EXPECT_EQ(describe_duration(3 * 86400), "3 days");
  EXPECT_EQ(describe_duration(1e300), "3.17e+292 years");
  EXPECT_EQ(describe_duration(std::numeric_limits<double>::infinity()), "forever");
}

TEST(RunEstimate, ScalesWithStepsElementsAndThreads) {
  // The model of solver/run_estimate.cpp: 10 us a step plus 300 ns + 18 ns (p + 1)^2 an element.
  const RunEstimate one = estimate_run({0, 1000}, 1000, 1);
  EXPECT_NEAR(one.seconds, 1000 * (10e-6 + 1000 * (300e-9 + 72e-9)), 1e-12);
  EXPECT_NEAR(estimate_run({0, 1000}, 2000, 1).seconds, 2 * one.seconds, 1e-12);
  EXPECT_NEAR(estimate_run({0, 1000}, 1000, 2).seconds, one.seconds / 1.8, 1e-12);
  // Counts far beyond any run stay finite numbers, so that the refusal can say them.
  EXPECT_TRUE(std::isfinite(estimate_run({0, 0, 0, 0, 0, 0, 0, 1e6}, 2.6e14, 1).seconds));
}

}  // namespace
}  // namespace hemotree
