#pragma once
/// \file
/// Statistics shared by the benchmark campaigns (frontend, heuristic): medians where an
/// unreached stage counts as +inf, and JSON numbers that turn non-finite values into null.

#include <algorithm>
#include <cmath>
#include <vector>

#include <nlohmann/json.hpp>

namespace miner::bench {

/// NaN marks an unknown value: a statistic over a list with one is unknown too.
inline bool any_unknown(const std::vector<double>& v) {
  return std::any_of(v.begin(), v.end(), [](double x) { return std::isnan(x); });
}

/// Median; +inf entries (stage not reached) take part, and a median that is +inf is NaN
/// ("fewer than half got there").
inline double median(std::vector<double> v) {
  if (v.empty() || any_unknown(v)) return NAN;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  // Lower median for even n keeps "+inf in the upper half" well defined.
  const double m = n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  return std::isfinite(m) ? m : NAN;
}

inline double mean(const std::vector<double>& v) {
  if (v.empty() || any_unknown(v)) return NAN;
  double s = 0.0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

inline nlohmann::json num(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

}  // namespace miner::bench
