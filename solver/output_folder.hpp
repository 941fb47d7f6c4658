// Where a run's results go, so that `--out DIR` never mixes two runs. Everything is written
// into DIR.partial, a sibling whose name says it is incomplete; when the run ends (complete,
// interrupted or broken down, as its summary.json says) that folder takes DIR's place in one
// rename (RENAME_EXCHANGE where the file system has it), and the previous results are then
// removed. After a kill at any moment DIR holds the previous complete results or the new
// ones, and DIR.partial what the killed run had (its last checkpoint, for --resume).
#pragma once

#include <filesystem>
#include <optional>

namespace hemotree {

class OutputFolder {
 public:
  // Refuses (InputError) a DIR that exists and is not a hemosolve results folder (not
  // empty, no summary.json), and a DIR.partial that a live hemosolve is writing.
  explicit OutputFolder(const std::filesystem::path& dir);

  const std::filesystem::path& final_path() const { return final_; }
  const std::filesystem::path& staging() const { return staging_; }  // write here

  // The newest checkpoint a run into DIR left: DIR.partial's (a killed run's), else DIR's.
  std::optional<std::filesystem::path> latest_checkpoint() const;

  // Creates DIR.partial afresh (removing a stale one that a dead run left) and records
  // its owner; returns true where it removed one.
  bool open();
  // DIR.partial becomes DIR; the previous results go.
  void publish();
  // A run that produced nothing to keep: DIR.partial goes, DIR stays as it was.
  void discard();

 private:
  std::filesystem::path final_, staging_, owner_;
};

}  // namespace hemotree
