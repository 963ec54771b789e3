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

/// The p-quantile (0 <= p <= 1) by linear interpolation between order statistics (type 7,
/// numpy's default); +inf entries (stage not reached) take part, and a quantile that lands
/// on one is NaN (null): e.g. the upper quartile when more than a quarter missed.
inline double quantile(std::vector<double> v, double p) {
  if (v.empty() || any_unknown(v)) return NAN;
  std::sort(v.begin(), v.end());
  const double h = p * static_cast<double>(v.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(h));
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  const double frac = h - static_cast<double>(lo);
  const double q = frac == 0.0 ? v[lo] : v[lo] + frac * (v[hi] - v[lo]);
  return std::isfinite(q) ? q : NAN;
}

/// Sample standard deviation (n - 1) of the finite entries; NaN for fewer than two or an
/// unknown (NaN) entry.
inline double stddev(const std::vector<double>& v) {
  if (any_unknown(v)) return NAN;
  std::vector<double> f;
  for (double x : v)
    if (std::isfinite(x)) f.push_back(x);
  if (f.size() < 2) return NAN;
  double m = 0.0;
  for (double x : f) m += x;
  m /= static_cast<double>(f.size());
  double ss = 0.0;
  for (double x : f) ss += (x - m) * (x - m);
  return std::sqrt(ss / static_cast<double>(f.size() - 1));
}

inline nlohmann::json num(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

}  // namespace miner::bench
