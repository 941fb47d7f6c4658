// A progress line on stderr, redrawn in place, shown only when stderr is a terminal so that
// pipes and logs stay quiet.
#pragma once

#include <chrono>
#include <cstddef>
#include <string>

namespace hemotree {

class Progress {
 public:
  Progress(std::string label, std::size_t total);
  ~Progress();
  void update(std::size_t done);  // cheap: redraws at most a few times a second
  void finish();

 private:
  std::string label_;
  std::size_t total_;
  bool enabled_;
  bool finished_ = false;
  std::chrono::steady_clock::time_point start_, last_draw_;
};

}  // namespace hemotree
