#pragma once
/// \file
/// Exact binomial sizing for statistical tests (REQ-HARNESS-005).
///
/// A statistical test runs n independent seeded trials and passes if at least k succeed.
/// If the claimed success probability is p0, the test fails by chance with probability
/// P(X < k | n, p0) (X ~ Binomial(n, p0)); `min_successes` picks the largest k whose
/// false-fail probability stays <= alpha, so a test is as strict as its budget allows
/// without flaking more than alpha. `binomial_cdf` is summed exactly in log space.

#include <cmath>
#include <stdexcept>

namespace miner::testing {

/// log C(n, i) via lgamma.
inline double log_choose(int n, int i) {
  return std::lgamma(n + 1.0) - std::lgamma(i + 1.0) - std::lgamma(n - i + 1.0);
}

/// P(X <= k) for X ~ Binomial(n, p), exact term by term.
inline double binomial_cdf(int k, int n, double p) {
  if (k < 0) return 0.0;
  if (k >= n) return 1.0;
  if (p <= 0.0) return 1.0;
  if (p >= 1.0) return 0.0;
  double sum = 0.0;
  for (int i = 0; i <= k; ++i) {
    sum += std::exp(log_choose(n, i) + i * std::log(p) + (n - i) * std::log1p(-p));
  }
  return std::min(sum, 1.0);
}

/// The largest k with P(X < k | n, p0) <= alpha: pass iff successes >= k.
inline int min_successes(int n, double p0, double alpha) {
  if (n < 1 || !(p0 > 0.0 && p0 <= 1.0) || !(alpha > 0.0 && alpha < 1.0)) {
    throw std::invalid_argument("min_successes: need n >= 1, p0 in (0, 1], alpha in (0, 1)");
  }
  int k = 0;
  while (k < n && binomial_cdf(k, n, p0) <= alpha) ++k;  // P(X <= k) = P(X < k + 1)
  return k;
}

/// False-fail rate used by every statistical test: ~1e-6 (../shared/anchors.md).
inline constexpr double kFalseFailRate = 1e-6;

}  // namespace miner::testing
