// hemosolve's output folder: a run writes into OUT.partial, which replaces OUT whole; a
// folder of other files is never replaced; a live writer's staging folder is never taken,
// however many runs start into it at once; a dead one's is.
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "core/errors.hpp"
#include "formats/checkpoint_file.hpp"
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
  {
    OutputFolder live(out);  // holds run's lock: a second writer, in any process, is refused
    try {
      OutputFolder second(out);
      FAIL() << "two writers of one folder";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("hemosolve (process " + std::to_string(::getpid()) + ") is writing " +
                                           out.string() + ".partial; wait for it"),
                std::string::npos)
          << e.what();
    }
    live.open();
    write(live.staging() / "checkpoint.bin", "x");
    EXPECT_TRUE(fs::exists(staging / "checkpoint.bin"));  // the refused one removed nothing
  }
  // Its process gone (here: its lock let go without publishing), the folder is a dead run's,
  // whatever process ids came and went; an owner file of an earlier version is no owner.
  write(staging / ".hemosolve-owner", std::to_string(::getpid()) + "\n");
  fs::create_directories(staging / "frames");
  write(staging / "frames" / "frames.pvd", "last cycle");
  OutputFolder f(out);
  ASSERT_TRUE(f.latest_checkpoint());
  EXPECT_EQ(*f.latest_checkpoint(), staging / "checkpoint.bin");
  EXPECT_TRUE(f.open());  // the dead run's folder goes, its frames too unless kept
  EXPECT_FALSE(fs::exists(staging / "checkpoint.bin"));
  EXPECT_FALSE(fs::exists(staging / "frames"));
  EXPECT_FALSE(fs::exists(out.string() + ".partial.stale"));
  f.discard();
  EXPECT_FALSE(fs::exists(staging));
  EXPECT_FALSE(fs::exists(out));
}

// A run killed before its first checkpoint left a frame or a temporary: its folder is still
// known for hemosolve's, and taken over.
TEST(OutputFolder, TakesOverARunKilledEarly) {
  Scratch s;
  const fs::path out = s.dir / "run";
  {
    OutputFolder killed(out);
    killed.open();
    fs::create_directories(killed.staging() / "frames");
    write(killed.staging() / "frames" / "frames_0000.vtp", "half");
  }  // its lock let go, as the kernel does for a killed process
  OutputFolder next(out);
  EXPECT_TRUE(next.open());
  EXPECT_FALSE(fs::exists(next.staging() / "frames"));
}

// A resume at the run's end publishes the frames the killed run wrote of its last cycle.
TEST(OutputFolder, KeepsADeadRunsFramesWhenAsked) {
  Scratch s;
  const fs::path out = s.dir / "run", staging = out.string() + ".partial";
  fs::create_directories(staging / "frames");
  write(staging / "checkpoint.bin", "x");
  write(staging / "frames" / "frames_0000.vtp", "frame");
  OutputFolder f(out);
  EXPECT_TRUE(f.open(true));
  EXPECT_EQ(read(staging / "frames" / "frames_0000.vtp"), "frame");
  EXPECT_FALSE(fs::exists(staging / "checkpoint.bin"));
  f.publish();
  EXPECT_EQ(read(out / "frames" / "frames_0000.vtp"), "frame");
}

// A resume of a killed run holds its checkpoint open: the folder's opening moves it into the new
// folder under the name asked (the run's first snapshot), the very file the reader reads, before
// the dead run's folder is removed (NFS cannot remove a folder holding a file still open).
TEST(OutputFolder, KeepsADeadRunsCheckpointWhenAsked) {
  Scratch s;
  const fs::path out = s.dir / "run", staging = out.string() + ".partial";
  fs::create_directories(staging);
  CheckpointWriter writer;
  writer.section("a");
  writer.put(1.5);
  write_checkpoint_file(staging / "checkpoint.bin", writer.bytes());
  CheckpointReader held(staging / "checkpoint.bin");
  OutputFolder f(out);
  EXPECT_TRUE(f.open(false, "snapshot.pending"));
  EXPECT_FALSE(fs::exists(staging / "checkpoint.bin"));
  EXPECT_TRUE(held.reads(staging / "snapshot.pending"));
  EXPECT_EQ(read(staging / "snapshot.pending"), writer.bytes());
  held.write_copy(s.dir / "copy.bin");  // not the same file: a copy
  EXPECT_FALSE(held.reads(s.dir / "copy.bin"));
  EXPECT_FALSE(held.reads(s.dir / "none.bin"));
}

// Many writers started at once: exactly one takes the folder, every other is refused while
// it holds it, and nothing of the winner's is touched. (flock excludes open file
// descriptions, so threads of one process contend as processes would.)
TEST(OutputFolder, OneWriterOfManyStartedAtOnce) {
  Scratch s;
  const fs::path out = s.dir / "run";
  for (int round = 0; round < 40; ++round) {
    constexpr int writers = 6;
    std::atomic<int> ready{0}, won{0}, refused{0}, attempted{0};
    std::vector<std::thread> threads;
    for (int w = 0; w < writers; ++w)
      threads.emplace_back([&, w] {
        ++ready;
        while (ready < writers) std::this_thread::yield();  // all start together
        std::optional<OutputFolder> f;
        try {
          f.emplace(out);
        } catch (const InputError&) {
          ++refused;
        }
        ++attempted;
        if (!f) return;
        ++won;
        f->open();
        write(f->staging() / "summary.json", std::to_string(round) + " " + std::to_string(w));
        while (attempted < writers) std::this_thread::yield();  // held until every other has tried
        f->publish();
      });
    for (auto& t : threads) t.join();
    ASSERT_EQ(won, 1) << "round " << round;
    ASSERT_EQ(refused, writers - 1);
    EXPECT_EQ(read(out / "summary.json").substr(0, std::to_string(round).size() + 1), std::to_string(round) + " ");
    EXPECT_FALSE(fs::exists(out.string() + ".partial"));
  }
  // Nothing but the results is left beside them: the lock file goes with its holder.
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(s.dir)) ++entries;
  EXPECT_EQ(entries, 1u);
}

// A lock file that is not this run's any more (removed by hand) stops the run from renaming
// a folder that another run may now be writing.
TEST(OutputFolder, PublishesOnlyWhileItHoldsTheFolder) {
  Scratch s;
  const fs::path out = s.dir / "run";
  OutputFolder f(out);
  f.open();
  write(f.staging() / "summary.json", "mine");
  fs::remove(s.dir / ".run.hemosolve-lock");
  OutputFolder other(out);  // now possible
  EXPECT_THROW(f.publish(), IoError);
  EXPECT_FALSE(fs::exists(out));
}

// A run refused before open() leaves nothing: no lock file, no parent folders it made.
TEST(OutputFolder, ARunThatNeverOpenedLeavesNothing) {
  Scratch s;
  { OutputFolder f(s.dir / "a" / "b" / "run"); }
  EXPECT_FALSE(fs::exists(s.dir / "a"));
  EXPECT_TRUE(fs::is_empty(s.dir));
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
  // A 0D system spread over ranks: 0.4 ms a solve and 1 us a node of the rank, two solves a
  // step (one coupling node) over 500 nodes, on no thread's speed-up (its calls are collective).
  EXPECT_NEAR(estimate_run({0, 1000}, 1000, 2, 1, 0, 2, 500).seconds - one.seconds / 1.8, 1000 * 2 * (0.4e-3 + 500e-6), 1e-12);
  // Counts far beyond any run stay finite numbers, so that the refusal can say them.
  EXPECT_TRUE(std::isfinite(estimate_run({0, 0, 0, 0, 0, 0, 0, 1e6}, 2.6e14, 1).seconds));
}

}  // namespace
}  // namespace hemotree
