// Where a run's results go, so that `--out DIR` never mixes two runs. Everything is written
// into DIR.partial, a sibling whose name says it is incomplete; when the run ends (complete,
// interrupted or broken down, as its summary.json says) that folder takes DIR's place in one
// rename (RENAME_EXCHANGE where the file system has it), and the previous results are then
// removed. After a kill at any moment DIR holds the previous complete results or the new
// ones, and DIR.partial what the killed run had (its last checkpoint, for --resume).
//
// One run at a time owns DIR: from its constructor to its end a run holds an exclusive
// flock(2) on DIR's lock file, .DIR.hemosolve-lock beside it, and only the holder creates,
// takes over, renames or removes DIR.partial. The kernel releases the lock when the process
// ends however it ends, so a killed run's folder is free at once and a live run's never is
// (no process id to outlive its process or to be reused). The holder removes the lock file
// when it is done; a run that locked a file that is no longer at its name tries again.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

namespace hemotree {

class OutputFolder {
 public:
  // Takes DIR for this run. Refuses (InputError) a DIR that exists and is not a hemosolve
  // results folder (not empty, no summary.json), a DIR.partial that another live hemosolve
  // is writing ("hemosolve (process N) is writing DIR.partial") and a DIR.partial that is
  // not hemosolve's. Creates DIR's missing parent folders (removed again, if still empty,
  // should the run end before open()).
  explicit OutputFolder(const std::filesystem::path& dir);
  ~OutputFolder();  // lets DIR go
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;

  const std::filesystem::path& final_path() const { return final_; }
  const std::filesystem::path& staging() const { return staging_; }  // write here

  // The newest checkpoint a run into DIR left: DIR.partial's (a killed run's), else DIR's.
  std::optional<std::filesystem::path> latest_checkpoint() const;

  // Creates DIR.partial afresh; a stale one (a dead run's) is first renamed aside, then
  // removed, so that a kill meanwhile never leaves half of it looking like a staging folder.
  // keep_frames: the stale folder's frames/ go into the new one (the frames of the killed
  // run's last cycle, which a resume with no cycle left publishes). keep_checkpoint_as: where
  // given, the stale folder's checkpoint.bin goes into the new one under this name (the
  // checkpoint a resume continues from, which may be held open: moved, not removed, it leaves
  // no file of an open descriptor in a folder being removed, which NFS cannot remove).
  // Returns true where there was a stale folder.
  bool open(bool keep_frames = false, const std::string& keep_checkpoint_as = {});
  // DIR.partial becomes DIR; the previous results go.
  void publish();
  // A run that produced nothing to keep: DIR.partial goes, DIR stays as it was.
  void discard();

 private:
  // IoError unless this run still holds DIR's lock (someone removed or replaced the file).
  void check_claim(const char* doing) const;
  void release() noexcept;  // the lock, and the parents made where the run never opened

  std::filesystem::path final_, staging_, lock_, stale_;
  std::filesystem::path made_parent_;  // the topmost parent folder the constructor created
  int lock_fd_ = -1;
  bool opened_ = false;
};

}  // namespace hemotree
