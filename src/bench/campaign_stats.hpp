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

/// Two-sided p-value of the Mann-Whitney U test that two samples come from one
/// distribution (normal approximation with the tie correction and a continuity correction of
/// 1/2, as scipy.stats.mannwhitneyu's asymptotic method). +inf entries (a missed stage) take
/// part as ties above every finite value. NaN when a sample is empty or holds NaN; 1 when all
/// values tie.
inline double mann_whitney_p(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.empty() || b.empty() || any_unknown(a) || any_unknown(b)) return NAN;
  std::vector<std::pair<double, int>> all;
  for (double x : a) all.emplace_back(x, 0);
  for (double x : b) all.emplace_back(x, 1);
  std::sort(all.begin(), all.end(), [](const auto& l, const auto& r) { return l.first < r.first; });
  const double n = static_cast<double>(all.size()), na = static_cast<double>(a.size()), nb = static_cast<double>(b.size());
  double rank_a = 0.0, ties = 0.0;
  for (std::size_t i = 0; i < all.size();) {
    std::size_t j = i;
    while (j < all.size() && all[j].first == all[i].first) ++j;  // +inf == +inf: one tie group
    const double t = static_cast<double>(j - i), mid = 0.5 * static_cast<double>(i + 1 + j);  // average rank
    for (std::size_t k = i; k < j; ++k)
      if (all[k].second == 0) rank_a += mid;
    ties += t * t * t - t;
    i = j;
  }
  const double U = rank_a - na * (na + 1.0) / 2.0, mu = na * nb / 2.0;
  const double var = na * nb / 12.0 * ((n + 1.0) - ties / (n * (n - 1.0)));
  if (!(var > 0.0)) return 1.0;
  const double z = std::max(0.0, std::abs(U - mu) - 0.5) / std::sqrt(var);
  return std::min(1.0, std::erfc(z / std::sqrt(2.0)));
}

inline nlohmann::json num(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

}  // namespace miner::bench
