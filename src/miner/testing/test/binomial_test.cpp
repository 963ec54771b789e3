#include <catch2/catch.hpp>

#include <cstdlib>
#include <tuple>

#include "miner/testing/binomial.hpp"

using miner::testing::binomial_cdf;
using miner::testing::min_successes;

TEST_CASE("The binomial CDF matches hand-computed values", "[REQ-HARNESS-005]") {
  // n = 3, p = 1/2: P(X <= 0) = 1/8, P(X <= 1) = 1/2, P(X <= 2) = 7/8.
  CHECK(binomial_cdf(0, 3, 0.5) == Approx(0.125).epsilon(1e-14));
  CHECK(binomial_cdf(1, 3, 0.5) == Approx(0.5).epsilon(1e-14));
  CHECK(binomial_cdf(2, 3, 0.5) == Approx(0.875).epsilon(1e-14));
  CHECK(binomial_cdf(3, 3, 0.5) == 1.0);
  CHECK(binomial_cdf(-1, 3, 0.5) == 0.0);
  // n = 10, p = 0.9: P(X <= 8) = 1 - P(9) - P(10) = 1 - 10 * 0.9^9 * 0.1 - 0.9^10.
  const double p9 = 10 * std::pow(0.9, 9) * 0.1, p10 = std::pow(0.9, 10);
  CHECK(binomial_cdf(8, 10, 0.9) == Approx(1 - p9 - p10).epsilon(1e-12));
}

TEST_CASE("min_successes reproduces the anchor sizing 0.99 vs 0.90 with N 291 and k 277", "[REQ-HARNESS-005]") {
  const int k = min_successes(291, 0.99, 1e-6);
  CHECK(k == 277);
  // The defining property: false-fail <= alpha at k, > alpha at k + 1.
  CHECK(binomial_cdf(k - 1, 291, 0.99) <= 1e-6);
  CHECK(binomial_cdf(k, 291, 0.99) > 1e-6);
  // ... and it has power against p = 0.90: such a planner passes with P ~ 9.7e-4.
  CHECK(1.0 - binomial_cdf(k - 1, 291, 0.90) < 1e-3);
}

TEST_CASE("min_successes rejects meaningless arguments", "[REQ-HARNESS-005]") {
  CHECK_THROWS_AS(min_successes(0, 0.9, 1e-6), std::invalid_argument);
  CHECK_THROWS_AS(min_successes(10, 0.0, 1e-6), std::invalid_argument);
  CHECK_THROWS_AS(min_successes(10, 0.9, 0.0), std::invalid_argument);
  CHECK(min_successes(10, 1.0, 1e-6) == 10);
}

TEST_CASE("size_binomial_test finds the smallest n holding both error rates, by the exact binomial", "[REQ-HARNESS-005]") {
  using miner::testing::binomial_cdf;
  using miner::testing::size_binomial_test;
  // Values checked against scipy.stats.binom (sf / cdf) by the same search.
  const auto a = size_binomial_test(0.999, 0.9);
  CHECK(a.n == 143);
  CHECK(a.k == 139);
  const auto b = size_binomial_test(0.999, 0.8);
  CHECK(b.n == 61);
  CHECK(b.k == 58);
  const auto c = size_binomial_test(0.6, 0.3);
  CHECK(c.n == 163);
  CHECK(c.k == 68);
  for (const auto& t : {a, b, c}) {
    CHECK(t.false_fail <= 1e-6);
    CHECK(t.miss <= 1e-3);
  }
  // Minimal: one trial fewer misses one of the two rates.
  for (const auto& [p0, p1, t] : {std::tuple{0.999, 0.9, a}, std::tuple{0.999, 0.8, b}, std::tuple{0.6, 0.3, c}}) {
    const int n = t.n - 1;
    const int k = miner::testing::min_successes(n, p0, 1e-6);
    CHECK(1.0 - binomial_cdf(k - 1, n, p1) > 1e-3);
  }
  // The examples of weak tests: 16 trials needing 14 pass a 0.8 planner 35 % of the
  // time; 60 needing 57 pass a 0.9 planner 14 % of the time (13.7 %).
  CHECK(1.0 - binomial_cdf(13, 16, 0.8) == Approx(0.352).margin(0.001));
  CHECK(1.0 - binomial_cdf(56, 60, 0.9) == Approx(0.137).margin(0.001));
}

TEST_CASE("size_binomial_test refuses alternatives it cannot separate", "[REQ-HARNESS-005]") {
  using miner::testing::size_binomial_test;
  CHECK_THROWS_AS(size_binomial_test(0.9, 0.95), std::invalid_argument);  // p1 must be below p0
  CHECK_THROWS_AS(size_binomial_test(0.9, 0.9), std::invalid_argument);
  CHECK_THROWS_AS(size_binomial_test(0.9, 0.0), std::invalid_argument);
  CHECK_THROWS_AS(size_binomial_test(0.9, 0.5, 0.0), std::invalid_argument);
  CHECK_THROWS_AS(size_binomial_test(0.999, 0.998, 1e-6, 1e-3, 100), std::domain_error);
}

TEST_CASE("Seed sets: 0 is CI's seed, others mix it, MINER_SEED_SET chooses", "[REQ-HARNESS-005]") {
  using miner::testing::seed_for_set;
  CHECK(seed_for_set(12345, 0) == 12345);
  CHECK(seed_for_set(12345, 1) != 12345);
  CHECK(seed_for_set(12345, 1) != seed_for_set(12345, 2));
  ::setenv("MINER_SEED_SET", "2", 1);
  CHECK(miner::testing::seed_set() == 2);
  ::setenv("MINER_SEED_SET", "x", 1);
  CHECK_THROWS_AS(miner::testing::seed_set(), std::invalid_argument);
  ::unsetenv("MINER_SEED_SET");
  CHECK(miner::testing::seed_set() == 0);
}

TEST_CASE("binomial_interval bounds a count on both sides at the stated rate", "[REQ-HARNESS-005]") {
  using miner::testing::binomial_cdf;
  const auto iv = miner::testing::binomial_interval(1000, 0.3, 1e-6);
  CHECK(binomial_cdf(static_cast<int>(iv.lo) - 1, 1000, 0.3) <= 5e-7);
  CHECK(binomial_cdf(static_cast<int>(iv.lo), 1000, 0.3) > 5e-7);      // as tight as allowed
  CHECK(1.0 - binomial_cdf(static_cast<int>(iv.hi), 1000, 0.3) <= 5e-7);
  CHECK(1.0 - binomial_cdf(static_cast<int>(iv.hi) - 1, 1000, 0.3) > 5e-7);
  CHECK(iv.lo < 300);
  CHECK(iv.hi > 300);
  const auto edge = miner::testing::binomial_interval(10, 1.0);
  CHECK(edge.lo == 10);
  CHECK(edge.hi == 10);
  CHECK_THROWS_AS(miner::testing::binomial_interval(10, 1.5), std::invalid_argument);
}
