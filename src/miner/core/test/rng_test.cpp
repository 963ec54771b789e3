#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

#include "miner/core/rng.hpp"

using miner::Rng;

TEST_CASE("Same seed and stream give the same sequence and other streams differ", "[REQ-CORE-001]") {
  Rng a(42, 7), b(42, 7), c(42, 8), d(43, 7);
  bool differs_c = false, differs_d = false;
  for (int i = 0; i < 1000; ++i) {
    const auto x = a.next_u64();
    REQUIRE(x == b.next_u64());
    differs_c |= x != c.next_u64();
    differs_d |= x != d.next_u64();
  }
  CHECK(differs_c);
  CHECK(differs_d);
}

TEST_CASE("Retries of small seeds never share a stream: no seed's retry is another seed's draw", "[REQ-CORE-001]") {
  // A generator that redraws seeds Rng(seed, retry_stream(attempt)); with the plain attempt as
  // the stream, retry 3 of seed 1 was the first draw of seed 2 (1 ^ 3 == 2 ^ 0).
  std::set<std::uint64_t> first_outputs;
  for (std::uint64_t seed = 0; seed < 256; ++seed)
    for (std::uint64_t attempt = 0; attempt < 16; ++attempt)
      first_outputs.insert(Rng(seed, miner::retry_stream(attempt)).next_u64());
  CHECK(first_outputs.size() == 256u * 16u);
  CHECK(miner::retry_stream(0) == 0);  // a first try keeps the stream it always had
}

TEST_CASE("SplitMix64 matches its published reference values", "[REQ-CORE-001]") {
  // Reference: the SplitMix64 generator of Vigna (prng.di.unimi.it) seeded with 0 gives
  // 0xE220A8397B1DCDAF first; splitmix64(x) here is one step from state x.
  CHECK(miner::splitmix64(0) == 0xE220A8397B1DCDAFULL);
  CHECK(miner::splitmix64(0x9E3779B97F4A7C15ULL) == 0x6E789E6AA1B965F4ULL);
}

TEST_CASE("uniform01 stays in the half-open unit interval and uniform(lo, hi) below hi", "[REQ-CORE-001]") {
  Rng rng(1);
  for (int i = 0; i < 100000; ++i) {
    const double u = rng.uniform01();
    REQUIRE(u >= 0.0);
    REQUIRE(u < 1.0);
    const double v = rng.uniform(-3.0, 5.0);
    REQUIRE(v >= -3.0);
    REQUIRE(v < 5.0);
  }
}

TEST_CASE("uniform_index is unbiased over a small range and rejects n = 0", "[REQ-CORE-001]") {
  Rng rng(2);
  constexpr int kBins = 7, kDraws = 70000;
  std::vector<int> counts(kBins, 0);
  for (int i = 0; i < kDraws; ++i) {
    const auto k = rng.uniform_index(kBins);
    REQUIRE(k < kBins);
    ++counts[k];
  }
  // Chi-square with 6 degrees of freedom; 22.46 is its 0.999 quantile, so a correct
  // generator fails this fixed-seed check with probability 1e-3 — and the seed is fixed.
  double chi2 = 0.0;
  const double expected = static_cast<double>(kDraws) / kBins;
  for (int c : counts) chi2 += (c - expected) * (c - expected) / expected;
  CHECK(chi2 < 22.46);
  CHECK_THROWS_AS(rng.uniform_index(0), std::invalid_argument);
  CHECK(rng.uniform_index(1) == 0);
}

TEST_CASE("normal() has mean 0, variance 1 and normal tails", "[REQ-CORE-001]") {
  Rng rng(3);
  constexpr int kN = 200000;
  double sum = 0.0, sum2 = 0.0;
  int beyond2 = 0;
  for (int i = 0; i < kN; ++i) {
    const double x = rng.normal();
    sum += x;
    sum2 += x * x;
    beyond2 += std::fabs(x) > 2.0;
  }
  const double mean = sum / kN, var = sum2 / kN - mean * mean;
  // Standard errors: mean 1/sqrt(N) = 0.0022, variance sqrt(2/N) = 0.0032; 5 sigma bounds.
  CHECK(std::fabs(mean) < 5 * 0.0022);
  CHECK(std::fabs(var - 1.0) < 5 * 0.0032);
  // P(|x| > 2) = 0.0455; binomial standard error sqrt(p(1-p)/N) = 0.00047; 5 sigma.
  CHECK(std::fabs(static_cast<double>(beyond2) / kN - 0.0455) < 5 * 0.00047);
  Rng shifted(3);
  CHECK(shifted.normal(10.0, 2.0) == Approx(10.0 + 2.0 * Rng(3).normal()).epsilon(1e-15));
}

TEST_CASE("normal() draws its pairs independently: no correlation between the two of a pair", "[REQ-CORE-001]") {
  // The polar method yields two normals per accepted (u, v); a held-out mutant (session 23)
  // returned u * factor twice, so every second draw repeated the first while the moments held.
  Rng rng(11);
  constexpr int kPairs = 100000;
  double sxy = 0.0, sxx = 0.0, syy = 0.0;
  int equal = 0;
  for (int i = 0; i < kPairs; ++i) {
    const double x = rng.normal(), y = rng.normal();
    sxy += x * y;
    sxx += x * x;
    syy += y * y;
    equal += x == y;
  }
  // Under independence the sample correlation has standard error 1/sqrt(n) = 0.0032: 6 sigma.
  CHECK(std::fabs(sxy / std::sqrt(sxx * syy)) < 6.0 / std::sqrt(static_cast<double>(kPairs)));
  CHECK(equal == 0);
  // The stream is frozen (REQ-CORE-001): the first draws of seed 1 are these on every platform.
  // (Printed with %.17g; compared within 1e-14 relative, the room std::log may take between
  // C libraries.)
  Rng frozen(1);
  CHECK(frozen.normal() == Approx(0.08041642134045629).epsilon(1e-14));
  CHECK(frozen.normal() == Approx(0.97271450413705274).epsilon(1e-14));
}

namespace {

/// Checks that xs look like draws of N(0, 1): mean and variance within 5
/// standard errors, Kolmogorov-Smirnov at alpha = 1e-6, the tail beyond the ziggurat's r
/// (reached only through its tail branch) within 5 binomial sd and not empty.
void check_standard_normal(std::vector<double> xs) {
  const auto n = static_cast<double>(xs.size());
  double sum = 0.0, sum2 = 0.0;
  int tail = 0;  // |x| > r = 3.6541528853610088
  for (double x : xs) {
    sum += x;
    sum2 += x * x;
    tail += std::fabs(x) > 3.6541528853610088;
  }
  const double mean = sum / n, var = sum2 / n - mean * mean;
  // 5 standard errors: mean 1/sqrt(N), variance sqrt(2/N).
  CHECK(std::fabs(mean) < 5.0 / std::sqrt(n));
  CHECK(std::fabs(var - 1.0) < 5.0 * std::sqrt(2.0 / n));
  // Kolmogorov-Smirnov against Phi: the critical value at alpha = 1e-6 is
  // sqrt(-ln(alpha / 2) / 2) / sqrt(N) = 2.78 / sqrt(N); a wrong layer or wedge shows as a
  // step in the empirical CDF far larger than that.
  std::sort(xs.begin(), xs.end());
  double d = 0.0;
  for (std::size_t k = 0; k < xs.size(); ++k) {
    const double phi = 0.5 * std::erfc(-xs[k] / std::sqrt(2.0));
    d = std::max({d, std::fabs(phi - static_cast<double>(k) / n), std::fabs(phi - static_cast<double>(k + 1) / n)});
  }
  CHECK(d < 2.78 / std::sqrt(n));
  // P(|x| > r) = erfc(r / sqrt 2) = 2.58e-4: ~103 of 400000, binomial sd ~10; 5 sd bounds.
  const double p_tail = std::erfc(3.6541528853610088 / std::sqrt(2.0));
  const double sd = std::sqrt(n * p_tail * (1.0 - p_tail));
  CHECK(std::fabs(tail - n * p_tail) < 5.0 * sd);
  CHECK(tail > 0);
  // Beyond the base layer's width x_0 = v / f(r) = 3.91 only the tail branch reaches: its
  // count must match P(|x| > 3.95) = 7.8e-5 (~31 of 400000, sd ~5.6; 5 sd bounds). A draw
  // that kept every core-or-not value (no tail, no wedge rejection) has none there.
  int far = 0;
  for (double x : xs) far += std::fabs(x) > 3.95;
  const double p_far = std::erfc(3.95 / std::sqrt(2.0));
  CHECK(std::fabs(far - n * p_far) < 5.0 * std::sqrt(n * p_far * (1.0 - p_far)));
  CHECK(far > 0);
}

}  // namespace

TEST_CASE("normal_ziggurat() is N(0, 1): closed layers, moments, CDF and tail", "[REQ-CORE-001]") {
  // The recurrence from (r, v) must close the top layer at area v (it is the whole check
  // that the 256 layers are right); 1e-9 is far above the 1e-11 the doubles reach.
  CHECK(std::fabs(miner::ziggurat_top_layer_area() - 1.0) < 1e-9);
  Rng rng(4);
  std::vector<double> xs(400000);
  for (double& x : xs) x = rng.normal_ziggurat();
  check_standard_normal(xs);
  // Same seed, same numbers; not the polar method's sequence.
  Rng a(9), b(9), c(9);
  for (int i = 0; i < 100; ++i) REQUIRE(a.normal_ziggurat() == b.normal_ziggurat());
  CHECK(Rng(9).normal_ziggurat() != c.normal());
}

TEST_CASE("fill_normal_ziggurat() is N(0, 1) with neighbours independent, the same for a seed", "[REQ-CORE-001]") {
  // Its first draws come from SplitMix64's sequence, not the engine: the same checks as
  // normal_ziggurat(), in float.
  Rng rng(4);
  std::vector<float> fs(400000);
  rng.fill_normal_ziggurat(fs.data(), fs.size());
  std::vector<double> xs(fs.begin(), fs.end());
  check_standard_normal(xs);
  // Neighbours are independent (a counter stream with a bad increment would correlate them):
  // lag-1 and lag-2 sample correlations within 6 standard errors 1/sqrt(N).
  for (std::size_t lag : {std::size_t{1}, std::size_t{2}}) {
    double sxy = 0.0, sxx = 0.0;
    for (std::size_t k = 0; k + lag < fs.size(); ++k) {
      sxy += static_cast<double>(fs[k]) * fs[k + lag];
      sxx += static_cast<double>(fs[k]) * fs[k];
    }
    CHECK(std::fabs(sxy / sxx) < 6.0 / std::sqrt(static_cast<double>(fs.size())));
  }
  // Same seed and stream, same values; another stream, others; one call's values are not the
  // next call's (each call draws its own key from the stream).
  std::vector<float> a(1000), b(1000), c(1000), a2(1000);
  Rng ra(9, 3), rb(9, 3), rc(9, 4);
  ra.fill_normal_ziggurat(a.data(), a.size());
  rb.fill_normal_ziggurat(b.data(), b.size());
  rc.fill_normal_ziggurat(c.data(), c.size());
  ra.fill_normal_ziggurat(a2.data(), a2.size());
  CHECK(a == b);
  CHECK(a != c);
  CHECK(a != a2);
}
