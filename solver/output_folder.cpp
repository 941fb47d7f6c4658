#include "solver/output_folder.hpp"

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <string>
#include <unistd.h>

#include "cli/errors.hpp"

namespace hemotree {

namespace fs = std::filesystem;

namespace {
constexpr const char* owner_file = ".hemosolve-owner";  // the writing process's id

bool is_results_folder(const fs::path& dir) {
  std::error_code ec;
  return fs::is_empty(dir, ec) || fs::exists(dir / "summary.json", ec) || fs::exists(dir / "checkpoint.bin", ec) ||
         fs::exists(dir / owner_file, ec);
}

// The process that owns a staging folder, if it still runs.
long live_owner(const fs::path& owner) {
  std::ifstream in(owner);
  long pid = 0;
  if (!(in >> pid) || pid <= 0) return 0;
  return (::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM) ? pid : 0;
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
}  // namespace

OutputFolder::OutputFolder(const fs::path& dir) {
  fs::path clean = fs::absolute(dir).lexically_normal();
  if (!clean.has_filename()) clean = clean.parent_path();  // "run/" -> "run"
  final_ = clean;
  staging_ = final_.string() + ".partial";
  owner_ = staging_ / owner_file;
  std::error_code ec;
  if (fs::exists(final_, ec) && (!fs::is_directory(final_, ec) || !is_results_folder(final_)))
    throw InputError("--out " + dir.string() + ": exists and is not a hemosolve results folder (no summary.json); "
                     "choose a new or empty folder");
  if (fs::exists(staging_, ec)) {
    if (const long pid = live_owner(owner_))
      throw InputError("--out " + dir.string() + ": hemosolve (process " + std::to_string(pid) + ") is writing " +
                       staging_.string() + "; wait for it or choose another folder");
    if (!fs::is_directory(staging_, ec) || !is_results_folder(staging_))
      throw InputError("--out " + dir.string() + ": " + staging_.string() +
                       " exists and was not made by hemosolve; move it away");
  }
}

std::optional<fs::path> OutputFolder::latest_checkpoint() const {
  std::error_code ec;
  for (const fs::path& dir : {staging_, final_})
    if (fs::exists(dir / "checkpoint.bin", ec)) return dir / "checkpoint.bin";
  return std::nullopt;
}

bool OutputFolder::open() {
  std::error_code ec;
  const bool stale = fs::exists(staging_, ec);
  if (stale) remove_folder(staging_);  // a dead run's (the constructor checked)
  fs::create_directories(final_.parent_path(), ec);
  if (!fs::create_directory(staging_, ec) || ec)
    throw IoError("cannot create " + staging_.string() + (ec ? ": " + ec.message() : std::string()));
  std::ofstream owner(owner_);
  owner << ::getpid() << '\n';
  if (!owner.flush()) throw IoError("cannot write " + owner_.string());
  return stale;
}

void OutputFolder::publish() {
  std::error_code ec;
  fs::remove(owner_, ec);
  sync_folder(staging_);
  if (!fs::exists(final_, ec)) {
    if (std::rename(staging_.c_str(), final_.c_str()) != 0)
      throw IoError("cannot rename " + staging_.string() + " to " + final_.string() + ": " + std::strerror(errno));
  } else if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, final_.c_str(), RENAME_EXCHANGE) == 0) {
    remove_folder(staging_);  // now the previous results
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
