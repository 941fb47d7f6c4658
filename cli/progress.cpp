#include "cli/progress.hpp"

#include <cstdio>

#include "cli/tool.hpp"

namespace hemotree {

Progress::Progress(std::string label, std::size_t total)
    : label_(std::move(label)), total_(total), enabled_(stderr_is_terminal()),
      start_(std::chrono::steady_clock::now()), last_draw_(start_) {}

Progress::~Progress() { finish(); }

void Progress::update(std::size_t done) {
  if (!enabled_ || finished_) return;
  auto now = std::chrono::steady_clock::now();
  if (now - last_draw_ < std::chrono::milliseconds(200)) return;
  last_draw_ = now;
  double elapsed = std::chrono::duration<double>(now - start_).count();
  double fraction = total_ ? static_cast<double>(done) / static_cast<double>(total_) : 0.0;
  double left = fraction > 0 ? elapsed * (1.0 - fraction) / fraction : 0.0;
  std::fprintf(stderr, "\r%s: %5.1f %%  %zu/%zu  %.0f s left   ", label_.c_str(),
               100.0 * fraction, done, total_, left);
  std::fflush(stderr);
}

void Progress::finish() {
  if (!enabled_ || finished_) return;
  finished_ = true;
  std::fprintf(stderr, "\r\033[K");  // clear the line: the result speaks for itself
  std::fflush(stderr);
}

}  // namespace hemotree
