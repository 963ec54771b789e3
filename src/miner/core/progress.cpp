#include "miner/core/progress.hpp"

#include <algorithm>
#include <cstdio>
#include <iostream>

#include <unistd.h>

namespace miner {

namespace {
constexpr int kWidth = 30;
}

ProgressBar::ProgressBar(std::ostream* out, std::string label, std::size_t total)
    : out_(out), label_(std::move(label)), total_(std::max<std::size_t>(total, 1)), start_(Clock::now()) {}

void ProgressBar::update(std::size_t done) {
  if (!out_ || finished_) return;
  done = std::min(done, total_);
  const int filled = static_cast<int>(kWidth * done / total_);
  // Redraw on each new percent as well, so slow items still show movement.
  const int key = filled * 1000 + static_cast<int>(100 * done / total_);
  if (key == drawn_ && done != total_) return;
  drawn_ = key;
  // Elapsed wall time, and the rest at the rate so far (terminal only: never in logs or files).
  const double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
  char times[64];
  if (done > 0 && done < total_)
    std::snprintf(times, sizeof times, "  %.0f s, ETA %.0f s   ", elapsed,
                  elapsed / static_cast<double>(done) * static_cast<double>(total_ - done));
  else
    std::snprintf(times, sizeof times, "  %.0f s   ", elapsed);
  *out_ << '\r' << label_ << " [" << std::string(static_cast<std::size_t>(filled), '#')
        << std::string(static_cast<std::size_t>(kWidth - filled), ' ') << "] " << done << '/' << total_ << times
        << std::flush;
  if (done == total_) finish();
}

void ProgressBar::finish() {
  if (!out_ || finished_) return;
  finished_ = true;
  *out_ << '\n' << std::flush;
}

ProgressBar::~ProgressBar() {
  if (drawn_ >= 0) finish();
}

std::ostream* terminal_stream() { return ::isatty(STDERR_FILENO) ? &std::cerr : nullptr; }

}  // namespace miner
