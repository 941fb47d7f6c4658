#include "solver/output_folder.hpp"

#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <fcntl.h>
#include <string>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/errors.hpp"
#include "core/setting_error.hpp"

namespace hemotree {

namespace fs = std::filesystem;

namespace {
// In a staging folder from its creation: hemosolve made it, even where a run killed early
// left nothing else in it but a frame or a temporary. Says who (for people; the lock decides).
constexpr const char* owner_file = ".hemosolve-owner";

bool is_results_folder(const fs::path& dir) {
  std::error_code ec;
  return fs::is_empty(dir, ec) || fs::exists(dir / "summary.json", ec) || fs::exists(dir / "checkpoint.bin", ec) ||
         fs::exists(dir / owner_file, ec);
}

void remove_folder(const fs::path& dir) {
  std::error_code ec;
  fs::remove_all(dir, ec);
  if (ec) throw IoError("cannot remove " + dir.string() + ": " + ec.message());
}

void sync_folder(const fs::path& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

bool same_file(int fd, const fs::path& name) {
  struct stat held, named;
  return ::fstat(fd, &held) == 0 && ::stat(name.c_str(), &named) == 0 && held.st_dev == named.st_dev &&
         held.st_ino == named.st_ino;
}

std::string host_name() {
  char name[256] = {};
  if (::gethostname(name, sizeof name - 1) != 0) return "?";
  return name;
}

// Who holds a lock file, as its holder wrote it ("PID HOST"): "hemosolve (process N)", with
// the host where it is another. The holder writes it just after it locks; until then the file
// is empty or names a killed run's process: read again for a moment.
std::string holder(int fd) {
  const std::string here = host_name();
  for (int attempt = 0; attempt < 100; ++attempt) {
    char text[300] = {};
    const ssize_t n = ::pread(fd, text, sizeof text - 1, 0);
    long pid = 0;
    char host[260] = {};
    if (n > 0 && std::sscanf(text, "%ld %259s", &pid, host) == 2 && pid > 0) {
      const bool local = host == here;
      if (!local || ::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM)
        return "hemosolve (process " + std::to_string(pid) + (local ? std::string() : " on " + std::string(host)) + ")";
    }
    ::usleep(2000);
  }
  return "another hemosolve";
}
}  // namespace

OutputFolder::OutputFolder(const fs::path& dir) {
  fs::path clean = fs::absolute(dir).lexically_normal();
  if (!clean.has_filename()) clean = clean.parent_path();  // "run/" -> "run"
  final_ = clean;
  staging_ = final_.string() + ".partial";
  stale_ = final_.string() + ".partial.stale";
  lock_ = final_.parent_path() / ('.' + final_.filename().string()).append(".hemosolve-lock");
  fs::path shown = dir.lexically_normal();  // as the user wrote it, for the messages
  if (!shown.has_filename()) shown = shown.parent_path();
  std::error_code ec;
  if (fs::exists(final_, ec) && (!fs::is_directory(final_, ec) || !is_results_folder(final_)))
    throw SettingError("out", placeholder("out") + " " + dir.string() + ": exists and is not a hemosolve results folder (no summary.json); "
                     "choose a new or empty folder");

  // The lock: its file must exist to be locked, and so must the folder it lies in.
  for (fs::path p = final_.parent_path(); !p.empty() && !fs::exists(p, ec); p = p.parent_path()) made_parent_ = p;
  fs::create_directories(final_.parent_path(), ec);
  if (ec) throw IoError("cannot create " + final_.parent_path().string() + ": " + ec.message());
  try {
    for (;;) {
      lock_fd_ = ::open(lock_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
      if (lock_fd_ < 0) throw IoError("cannot create " + lock_.string() + ": " + std::strerror(errno));
      if (::flock(lock_fd_, LOCK_EX | LOCK_NB) != 0) {
        const int error = errno;
        const std::string who = holder(lock_fd_);
        ::close(lock_fd_);
        lock_fd_ = -1;
        if (error == EWOULDBLOCK)
          throw SettingError("out", placeholder("out") + " " + shown.string() + ": " + who + " is writing " + shown.string() +
                           ".partial; wait for it or choose another folder");
        throw IoError("cannot lock " + lock_.string() + ": " + std::strerror(error));
      }
      // A run that was done removed the file it held after this one opened it: the lock
      // on that file excludes nobody now; the name's new file is the one to lock.
      if (same_file(lock_fd_, lock_)) break;
      ::close(lock_fd_);
      lock_fd_ = -1;
    }
    // One write of a fixed width, over whatever a killed holder wrote.
    std::string owner = std::to_string(::getpid()) + " " + host_name();
    owner.resize(std::max<std::size_t>(owner.size(), 280), ' ');
    owner += '\n';
    if (::pwrite(lock_fd_, owner.data(), owner.size(), 0) != static_cast<ssize_t>(owner.size()) ||
        ::ftruncate(lock_fd_, static_cast<off_t>(owner.size())) != 0)
      throw IoError("cannot write " + lock_.string() + ": " + std::strerror(errno));
    if (fs::exists(staging_, ec) && (!fs::is_directory(staging_, ec) || !is_results_folder(staging_)))
      throw SettingError("out", placeholder("out") + " " + shown.string() + ": " + staging_.string() + " exists and was not made by hemosolve; move it away");
  } catch (...) {
    release();
    throw;
  }
}

OutputFolder::~OutputFolder() { release(); }

void OutputFolder::release() noexcept {
  if (lock_fd_ >= 0) {
    // Removed while still held: a run that opened this file meanwhile sees it is no longer
    // the name's, and locks the name's new one.
    if (same_file(lock_fd_, lock_)) ::unlink(lock_.c_str());
    ::close(lock_fd_);
    lock_fd_ = -1;
  }
  if (opened_ || made_parent_.empty()) return;
  // The parent folders this run created, where they are still empty (remove() fails on any other).
  std::error_code ec;
  fs::path p = final_.parent_path();
  while (fs::remove(p, ec) && p != made_parent_) p = p.parent_path();
  made_parent_.clear();
}

void OutputFolder::check_claim(const char* doing) const {
  if (lock_fd_ < 0 || !same_file(lock_fd_, lock_))
    throw IoError("cannot " + std::string(doing) + " " + staging_.string() + ": its lock file " + lock_.string() +
                  " was removed or replaced while this run held it; another run may be writing there");
}

std::optional<fs::path> OutputFolder::latest_checkpoint() const {
  std::error_code ec;
  for (const fs::path& dir : {staging_, final_})
    if (fs::exists(dir / "checkpoint.bin", ec)) return dir / "checkpoint.bin";
  return std::nullopt;
}

bool OutputFolder::open(bool keep_frames, const std::string& keep_checkpoint_as) {
  check_claim("create");
  std::error_code ec;
  // What a run killed while removing a stale folder left (this run holds the lock: no one else's).
  if (fs::exists(stale_, ec)) remove_folder(stale_);
  const bool stale = fs::exists(staging_, ec);
  if (stale && std::rename(staging_.c_str(), stale_.c_str()) != 0)
    throw IoError("cannot rename " + staging_.string() + " to " + stale_.string() + ": " + std::strerror(errno));
  if (!fs::create_directory(staging_, ec) || ec)
    throw IoError("cannot create " + staging_.string() + (ec ? ": " + ec.message() : std::string(": it exists")));
  opened_ = true;
  std::ofstream owner(staging_ / owner_file);
  owner << ::getpid() << ' ' << host_name() << '\n';
  if (!owner.flush()) throw IoError("cannot write " + (staging_ / owner_file).string());
  if (stale) {
    if (keep_frames && fs::exists(stale_ / "frames", ec) &&
        std::rename((stale_ / "frames").c_str(), (staging_ / "frames").c_str()) != 0)
      throw IoError("cannot move " + (stale_ / "frames").string() + " into " + staging_.string() + ": " +
                    std::strerror(errno));
    if (!keep_checkpoint_as.empty() && fs::exists(stale_ / "checkpoint.bin", ec) &&
        std::rename((stale_ / "checkpoint.bin").c_str(), (staging_ / keep_checkpoint_as).c_str()) != 0)
      throw IoError("cannot move " + (stale_ / "checkpoint.bin").string() + " into " + staging_.string() + ": " +
                    std::strerror(errno));
    remove_folder(stale_);
  }
  return stale;
}

void OutputFolder::publish() {
  check_claim("publish");
  std::error_code ec;
  fs::remove(staging_ / owner_file, ec);
  sync_folder(staging_);
  if (!fs::exists(final_, ec)) {
    if (std::rename(staging_.c_str(), final_.c_str()) != 0)
      throw IoError("cannot rename " + staging_.string() + " to " + final_.string() + ": " + std::strerror(errno));
  } else if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, final_.c_str(), RENAME_EXCHANGE) == 0) {
    // Now the previous results: aside first, so that a kill while removing them leaves no
    // half of them where a killed run's staging folder would be.
    if (std::rename(staging_.c_str(), stale_.c_str()) != 0)
      throw IoError("cannot rename " + staging_.string() + " to " + stale_.string() + ": " + std::strerror(errno));
    remove_folder(stale_);
  } else {
    // No atomic exchange here (EINVAL: the file system lacks it): two renames, with the
    // previous results under DIR.previous for the moment between them.
    const fs::path previous = final_.string() + ".previous";
    if (fs::exists(previous, ec)) remove_folder(previous);
    if (std::rename(final_.c_str(), previous.c_str()) != 0 || std::rename(staging_.c_str(), final_.c_str()) != 0)
      throw IoError("cannot replace " + final_.string() + ": " + std::strerror(errno));
    remove_folder(previous);
  }
  sync_folder(final_.parent_path());
}

void OutputFolder::discard() {
  std::error_code ec;
  fs::remove_all(staging_, ec);
}

}  // namespace hemotree
