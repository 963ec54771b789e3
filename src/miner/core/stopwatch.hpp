#pragma once
/// \file
/// Wall-clock stage timing for benchmarks and run summaries (never for tests' assertions).

#include <chrono>

namespace miner {

/// Milliseconds of steady-clock time since `t0`.
inline double elapsed_ms(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace miner
