// The chi-square distribution against its closed form (REQ-CORE-005), on seeded random
// arguments: a second, independent check beside the tabulated quantiles of the EKF tests.
#include <catch2/catch.hpp>

#include <cmath>

#include "miner/core/rng.hpp"
#include "miner/core/statistics.hpp"

namespace {
/// F(x; 2m) = 1 - e^{-x/2} sum_{j<m} (x/2)^j / j! = e^{-x/2} sum_{j>=m} (x/2)^j / j!, and
/// Q = 1 - F = e^{-x/2} sum_{j<m} (x/2)^j / j!, each from its own positive series in long
/// double (no cancellation, so the lower tail is as accurate as the upper).
struct EvenK {
  long double cdf, upper;
};
EvenK even_closed_form(double x, int m) {
  const long double h = 0.5L * x;
  long double term = 1.0L, below = 0.0L;
  for (int j = 0; j < m; ++j) {
    below += term;
    term *= h / (j + 1);
  }
  long double above = 0.0L;  // term is now (x/2)^m / m!
  for (int j = m; term > 1e-40L * above || above == 0.0L; ++j) {
    above += term;
    term *= h / (j + 1);
    if (term == 0.0L) break;
  }
  return {std::exp(-h) * above, std::exp(-h) * below};
}
}  // namespace

TEST_CASE("The chi-square CDF matches the closed form for even k on random arguments", "[REQ-CORE-005]") {
  miner::Rng rng(20261126, 1);
  int compared = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const int m = 1 + static_cast<int>(rng.uniform_index(200));  // k = 2..400
    const double k = 2.0 * m;
    // x over the bulk of the distribution: mean k, standard deviation sqrt(2k).
    const double x = std::max(1e-3, k + rng.uniform(-4.0, 6.0) * std::sqrt(2.0 * k));
    const EvenK exact = even_closed_form(x, m);
    const double F = miner::chi_square_cdf(x, k);
    INFO("k " << k << ", x " << x << ": F " << F << ", closed form " << static_cast<double>(exact.cdf));
    // 1e-12 relative on the smaller of F and 1 - F (the tail that carries the information).
    if (exact.cdf < 0.5L)
      CHECK(std::abs(F - static_cast<double>(exact.cdf)) <= 1e-12 * static_cast<double>(exact.cdf));
    else
      CHECK(std::abs((1.0 - F) - static_cast<double>(exact.upper)) <= 1e-12 * static_cast<double>(exact.upper) + 2e-16);
    ++compared;
  }
  CHECK(compared == 2000);
}

TEST_CASE("Chi-square quantiles invert the CDF and grow with p and k", "[REQ-CORE-005]") {
  miner::Rng rng(20261126, 2);
  for (int trial = 0; trial < 2000; ++trial) {
    const double k = std::exp(rng.uniform(std::log(0.5), std::log(500.0)));  // real k, 0.5..500
    const double p = rng.uniform(1e-6, 1.0 - 1e-6);
    const double x = miner::chi_square_quantile(p, k);
    INFO("k " << k << ", p " << p << ", x " << x);
    REQUIRE(std::isfinite(x));
    CHECK(x > 0.0);
    CHECK(std::abs(miner::chi_square_cdf(x, k) - p) <= 1e-12 * std::min(p, 1.0 - p) + 4e-16);
    // Monotone in p (a larger probability, a larger quantile) and in k (more degrees of
    // freedom shift the distribution right).
    CHECK(miner::chi_square_quantile(std::min(p * 1.01, 0.5 * (p + 1.0)), k) > x);
    CHECK(miner::chi_square_quantile(p, k * 1.1) > x);
  }
  // Outside the domain: an error naming the argument, not a number; below 0 the CDF is 0.
  CHECK_THROWS_WITH(miner::chi_square_quantile(0.0, 3.0), Catch::Contains("0 < p < 1"));
  CHECK_THROWS_WITH(miner::chi_square_quantile(0.5, 0.0), Catch::Contains("k > 0"));
  CHECK_THROWS_WITH(miner::chi_square_cdf(1.0, std::nan("")), Catch::Contains("k > 0"));
  CHECK_THROWS_WITH(miner::chi_square_cdf(std::nan(""), 3.0), Catch::Contains("NaN"));
  CHECK(miner::chi_square_cdf(-1.0, 3.0) == 0.0);
}
