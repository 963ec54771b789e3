#pragma once
/// \file
/// A progress bar for long work (REQ-CORE-006): "label [#####     ] 42/100  12 s, ETA 17 s"
/// (elapsed wall time, and the rest at the rate so far) redrawn in place with a carriage return. Callers pass a stream only when it is a terminal
/// (`terminal_stream()`), so logs and pipes stay quiet.

#include <chrono>
#include <cstddef>
#include <iosfwd>
#include <string>

namespace miner {

class ProgressBar {
 public:
  /// `out` may be null (then nothing is printed). `total` >= 1.
  ProgressBar(std::ostream* out, std::string label, std::size_t total);
  /// Marks `done` items finished; redraws when the bar's width changes or at the end.
  void update(std::size_t done);
  /// Ends the line (idempotent).
  void finish();
  ~ProgressBar();

 private:
  using Clock = std::chrono::steady_clock;
  std::ostream* out_;
  std::string label_;
  std::size_t total_;
  int drawn_ = -1;
  bool finished_ = false;
  Clock::time_point start_;
};

/// std::cerr if standard error is a terminal, else null.
std::ostream* terminal_stream();

}  // namespace miner
