#include <catch2/catch.hpp>

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
