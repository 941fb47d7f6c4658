// OutputStream: a file takes its name only complete, and nothing of a killed writer stays.
#include <algorithm>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/inotify.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

#include <gtest/gtest.h>

#include "core/errors.hpp"
#include "formats/output_stream.hpp"
#include "formats/parallel_rows.hpp"

using namespace hemotree;
namespace fs = std::filesystem;

namespace {

// A fresh, empty folder per test.
fs::path fresh_folder(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() /
                       ("hemotree-output-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::vector<std::string> entries(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

std::string content(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void touch(const fs::path& file) { std::ofstream(file) << "stale"; }

// The host part of this machine's partial names, read back from partial_path.
std::string host_part(const std::string& path) {
  const std::string p = partial_path(path);
  const std::string prefix = path + ".partial-";
  const std::string rest = p.substr(prefix.size());
  return rest.substr(0, rest.rfind('-'));
}

// A process id that no process has: beyond any pid_max (at most 2^22 on Linux).
constexpr const char* dead_pid = "99999999";

}  // namespace

TEST(OutputStream, TheTargetAppearsOnlyAtCommitAndReplacesTheOldFileWhole) {
  const fs::path dir = fresh_folder("commit");
  const fs::path target = dir / "net.json";
  std::ofstream(target) << "old complete result";
  {
    OutputStream out(target.string());
    out << "new ";
    for (int i = 0; i < 300000; ++i) out << "0123456789";  // beyond the 1 MiB buffer
    // Half-way: the old file is untouched and nothing else is in the folder (the bytes go
    // into an anonymous file where the file system allows it, as ext4 and tmpfs do).
    EXPECT_EQ(content(target), "old complete result");
    if (out.temporary_path().empty()) {
      EXPECT_EQ(entries(dir), std::vector<std::string>{"net.json"});
    }
    out.commit();
  }
  EXPECT_EQ(entries(dir), std::vector<std::string>{"net.json"});
  EXPECT_EQ(fs::file_size(target), 4u + 3000000u);
  fs::remove_all(dir);
}

TEST(OutputStream, AnUncommittedFileLeavesTheFolderAsItWas) {
  for (const auto kind : {OutputStream::Temporary::anonymous_if_possible, OutputStream::Temporary::named}) {
    const fs::path dir = fresh_folder("uncommitted");
    const fs::path target = dir / "net.json";
    {
      OutputStream out(target.string(), kind);
      out << "{\"format\": ";
      if (kind == OutputStream::Temporary::named) {
        // The fallback's name says which host and process write it.
        EXPECT_EQ(out.temporary_path(), partial_path(target.string()));
        EXPECT_EQ(entries(dir), std::vector<std::string>{fs::path(partial_path(target.string())).filename().string()});
      }
    }  // no commit: as if the writer failed half-way
    EXPECT_TRUE(entries(dir).empty());
    fs::remove_all(dir);
  }
}

TEST(OutputStream, TheNamedFallbackCommitsLikeTheAnonymousFile) {
  const fs::path dir = fresh_folder("named");
  const fs::path target = dir / "tree.vtp";
  OutputStream out(target.string(), OutputStream::Temporary::named);
  out << "complete";
  out.commit();
  EXPECT_EQ(entries(dir), std::vector<std::string>{"tree.vtp"});
  EXPECT_EQ(content(target), "complete");
  fs::remove_all(dir);
}

TEST(OutputStream, SigtermRemovesTheNamedPartialFile) {
  const fs::path dir = fresh_folder("sigterm");
  const fs::path target = dir / "net.json";
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    OutputStream out(target.string(), OutputStream::Temporary::named);
    out << "half";
    out.write(std::string(2 << 20, 'x'));  // on disk, not only in the buffer
    ::raise(SIGTERM);
    ::_exit(0);  // not reached
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(WTERMSIG(status), SIGTERM);  // re-raised: the shell sees the signal
  EXPECT_TRUE(entries(dir).empty());
  fs::remove_all(dir);
}

TEST(OutputStream, SigkillLeavesNothingOrAPartialTheNextWriterRemoves) {
  const fs::path dir = fresh_folder("sigkill");
  const fs::path target = dir / "net.json";
  int ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    OutputStream out(target.string());
    out.write(std::string(3 << 20, 'x'));
    const char named = out.temporary_path().empty() ? 'a' : 'n';
    (void)!::write(ready[1], &named, 1);
    ::pause();  // killed here, half-way
    ::_exit(0);
  }
  char kind = 0;
  ASSERT_EQ(::read(ready[0], &kind, 1), 1);
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  ::close(ready[0]);
  ::close(ready[1]);
  if (kind == 'a') EXPECT_TRUE(entries(dir).empty()) << "an anonymous file stayed visible";
  else EXPECT_EQ(entries(dir).size(), 1u);
  {
    OutputStream next(target.string());  // the next writer of the same name
    next << "done";
    next.commit();
  }
  EXPECT_EQ(entries(dir), std::vector<std::string>{"net.json"});
  fs::remove_all(dir);
}

// The names a folder saw created or moved in, while f ran (inotify).
template <class F>
std::vector<std::string> names_created(const fs::path& dir, F f) {
  const int watch = ::inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
  if (watch < 0 || ::inotify_add_watch(watch, dir.c_str(), IN_CREATE | IN_MOVED_TO) < 0) {
    if (watch >= 0) ::close(watch);
    f();
    return {"(no inotify)"};
  }
  f();
  std::vector<std::string> names;
  alignas(inotify_event) char events[64 * 1024];
  for (ssize_t got; (got = ::read(watch, events, sizeof events)) > 0;)
    for (ssize_t at = 0; at < got;) {
      const auto* e = reinterpret_cast<const inotify_event*>(events + at);
      if (e->len > 0) names.push_back(e->name);
      at += static_cast<ssize_t>(sizeof(inotify_event) + e->len);
    }
  ::close(watch);
  return names;
}

// Issue 21, defect 13d: a kill -9 at the rename left NAME.partial-HOST-PID beside a new
// target; a target that does not exist yet is now linked in at its own name, with no other.
TEST(OutputStream, ANewTargetIsLinkedInUnderItsOwnNameOnly) {
  const fs::path dir = fresh_folder("fresh");
  const fs::path target = dir / "net.json";
  bool anonymous = false;
  const auto seen = names_created(dir, [&] {
    OutputStream out(target.string());
    anonymous = out.temporary_path().empty();
    out << "complete";
    out.commit();
  });
  if (!anonymous) GTEST_SKIP() << "no O_TMPFILE here: the named fallback is used";
  if (seen == std::vector<std::string>{"(no inotify)"}) GTEST_SKIP() << "no inotify here";
  EXPECT_EQ(seen, std::vector<std::string>{"net.json"});
  EXPECT_EQ(content(target), "complete");
  fs::remove_all(dir);
}

// An existing target is replaced by rename from the partial name (linkat cannot replace);
// a partial of this process's own id, left by a killed writer whose id we reuse, is no
// obstacle.
TEST(OutputStream, AnExistingTargetIsReplacedThroughThePartialName) {
  const fs::path dir = fresh_folder("replace");
  const fs::path target = dir / "net.json";
  std::ofstream(target) << "old";
  touch(partial_path(target.string()));
  {
    OutputStream out(target.string());
    out << "new";
    out.commit();
  }
  EXPECT_EQ(entries(dir), std::vector<std::string>{"net.json"});
  EXPECT_EQ(content(target), "new");
  fs::remove_all(dir);
}

TEST(OutputStream, OnlyPartialsOfProcessesGoneFromThisHostAreRemoved) {
  const fs::path dir = fresh_folder("stale");
  const std::string target = (dir / "net.json").string();
  const std::string host = host_part(target);
  touch(target + ".partial-" + dead_pid);                      // the older form, process gone
  touch(target + ".partial-" + host + "-" + dead_pid);         // this host, process gone
  touch(target + ".partial-" + host + "-1");                   // this host, init runs
  touch(target + ".partial-" + host + "-" + std::to_string(::getpid()));  // our own
  touch(target + ".partial-other-host-" + dead_pid);           // another host: never ours to judge
  touch(target + ".partial-notapid");                          // not a partial of ours
  touch((dir / "other.json.partial-").string() + dead_pid);    // another target
  EXPECT_EQ(remove_stale_partials(target), 2u);
  const std::vector<std::string> expected = [&] {
    std::vector<std::string> names = {"net.json.partial-" + host + "-1",
                                      "net.json.partial-" + host + "-" + std::to_string(::getpid()),
                                      "net.json.partial-notapid",
                                      "net.json.partial-other-host-" + std::string(dead_pid),
                                      "other.json.partial-" + std::string(dead_pid)};
    std::sort(names.begin(), names.end());
    return names;
  }();
  EXPECT_EQ(entries(dir), expected);
  fs::remove_all(dir);
}

TEST(OutputStream, AFullDiskIsReported) {
  if (!fs::is_character_file("/dev/full")) GTEST_SKIP() << "no /dev/full";
  EXPECT_THROW(
      {
        OutputStream out("/dev/full");
        for (int i = 0; i < 100000; ++i) out << "0123456789";
        out.commit();
      },
      IoError);
}

// Rows formatted in parallel blocks are written in their order: the bytes of a serial loop,
// for any count of threads and rows across the blocks' edges (4096 rows a block).
TEST(WriteRows, TheSameBytesForAnyThreads) {
  const fs::path dir = fresh_folder("rows");
  auto row = [](std::string& text, std::size_t i) { text += "row " + std::to_string(i * i) + (i % 7 ? "" : " seventh"); };
  for (const std::size_t rows : {std::size_t{0}, std::size_t{1}, std::size_t{4096}, std::size_t{3 * 4096 + 17}}) {
    std::string expected;
    for (std::size_t i = 0; i < rows; ++i) {
      if (i > 0) expected += ",\n";
      row(expected, i);
    }
    for (const int threads : {1, 2, 3}) {
      const fs::path file = dir / ("rows-" + std::to_string(rows) + "-" + std::to_string(threads));
      OutputStream out(file.string());
      write_rows(out, rows, threads, ",\n", row);
      out.commit();
      EXPECT_EQ(content(file), expected) << rows << " rows, " << threads << " threads";
    }
  }
  fs::remove_all(dir);
}

// A row that cannot be formatted stops the writing with its own exception, on any thread
// (an exception leaving an OpenMP region would end the process instead).
TEST(WriteRows, AFailingRowThrowsItsException) {
  const fs::path dir = fresh_folder("rows-failing");
  for (const int threads : {1, 2, 3}) {
    OutputStream out((dir / "rows").string());
    auto row = [](std::string& text, std::size_t i) {
      if (i == 3 * 4096 + 5) throw std::runtime_error("row " + std::to_string(i));
      text += "x";
    };
    EXPECT_THROW(write_rows(out, 5 * 4096, threads, "\n", row), std::runtime_error) << threads << " threads";
  }
  EXPECT_TRUE(entries(dir).empty());  // nothing committed
  fs::remove_all(dir);
}
