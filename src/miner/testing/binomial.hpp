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
#include <cstdint>
#include <cstdlib>
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
/// Miss rate every statistical test must hold against its stated alternative (issue 19).
inline constexpr double kMissRate = 1e-3;

/// A statistical test sized by power: H0 "success rate >= p0" (the claim) against the
/// alternative "success rate <= p1" (the broken implementation it must reject). With n trials
/// it passes iff successes >= k; false_fail = P(X < k | n, p0), miss = P(X >= k | n, p1).
struct BinomialTest {
  int n = 0;
  int k = 0;
  double false_fail = 0.0;
  double miss = 0.0;
};

/// The smallest n (<= n_max) whose threshold k = min_successes(n, p0, alpha) also gives
/// miss <= beta: the cheapest test with both error rates, by the exact binomial. Throws
/// std::invalid_argument unless 0 < p1 < p0 <= 1 and alpha, beta in (0, 1), and
/// std::domain_error when n_max trials cannot reach both.
inline BinomialTest size_binomial_test(double p0, double p1, double alpha = kFalseFailRate, double beta = kMissRate,
                                       int n_max = 100000) {
  if (!(p1 > 0.0 && p1 < p0 && p0 <= 1.0) || !(alpha > 0.0 && alpha < 1.0) || !(beta > 0.0 && beta < 1.0) ||
      n_max < 1) {
    throw std::invalid_argument("size_binomial_test: need 0 < p1 < p0 <= 1, alpha and beta in (0, 1), n_max >= 1");
  }
  for (int n = 1; n <= n_max; ++n) {
    const int k = min_successes(n, p0, alpha);
    const double miss = 1.0 - binomial_cdf(k - 1, n, p1);
    if (miss <= beta) return {n, k, binomial_cdf(k - 1, n, p0), miss};
  }
  throw std::domain_error("size_binomial_test: no n <= n_max separates p0 from p1 at these error rates");
}

/// [lo, hi] with P(X < lo) <= alpha / 2 and P(X > hi) <= alpha / 2 for X ~ Binomial(n, p): a
/// count outside it rejects "the rate is p" with a false-fail rate <= alpha (bisection on
/// the exact CDF).
struct CountInterval {
  long lo = 0, hi = 0;
};
inline CountInterval binomial_interval(int n, double p, double alpha = kFalseFailRate) {
  if (n < 0 || !(p >= 0.0 && p <= 1.0) || !(alpha > 0.0 && alpha < 1.0))
    throw std::invalid_argument("binomial_interval: need n >= 0, p in [0, 1], alpha in (0, 1)");
  // lo: the largest k with P(X <= k - 1) <= alpha / 2; hi: the smallest k with P(X > k) <= alpha / 2.
  int a = 0, b = n;  // P(X <= a - 1) = 0 <= alpha/2 always holds at a = 0
  while (a < b) {
    const int m = a + (b - a + 1) / 2;
    if (binomial_cdf(m - 1, n, p) <= alpha / 2) a = m; else b = m - 1;
  }
  const int lo = a;
  a = 0;
  b = n;
  while (a < b) {
    const int m = a + (b - a) / 2;
    if (1.0 - binomial_cdf(m, n, p) <= alpha / 2) b = m; else a = m + 1;
  }
  return {lo, a};
}

/// The seed set of a statistical test: 0 in CI's run; the `long` label runs the same tests
/// with MINER_SEED_SET = 1, 2, 3 (each test mixes it into its master seed), so each test is
/// not one fixed draw.
inline unsigned seed_set() {
  const char* v = std::getenv("MINER_SEED_SET");
  if (v == nullptr || *v == '\0') return 0;
  char* end = nullptr;
  const unsigned long s = std::strtoul(v, &end, 10);
  if (*end != '\0' || s > 1000) throw std::invalid_argument("MINER_SEED_SET must be an integer in [0, 1000]");
  return static_cast<unsigned>(s);
}

/// master seed for seed set s: the CI seed itself for s = 0, a SplitMix64-mixed one otherwise.
inline std::uint64_t seed_for_set(std::uint64_t master, unsigned s) {
  if (s == 0) return master;
  std::uint64_t z = master + 0x9e3779b97f4a7c15ULL * s;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

}  // namespace miner::testing
