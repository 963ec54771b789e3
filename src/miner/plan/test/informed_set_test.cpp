#include <catch2/catch.hpp>

#include <cmath>

#include "miner/core/rng.hpp"
#include "miner/plan/informed_set.hpp"

using miner::plan::ProlateHyperspheroid;
using V = Eigen::Vector3d;

TEST_CASE("Informed-set samples lie in the set and fill it uniformly", "[REQ-PLAN-002]") {
  const V a(1, 2, 3), b(4, -1, 5);
  const double c = 1.3 * (b - a).norm();
  const ProlateHyperspheroid set(a, b, c);
  miner::Rng rng(3);
  // Uniformity check against the volume: the fraction of samples in the inner set of
  // diameter c' (same foci) estimates measure(c') / measure(c).
  const ProlateHyperspheroid inner(a, b, 1.15 * (b - a).norm());
  const int n = 40000;
  int inside_inner = 0;
  for (int i = 0; i < n; ++i) {
    const V x = set.sample(rng);
    REQUIRE(set.contains(x));
    inside_inner += inner.contains(x);
  }
  const double expected = inner.measure() / set.measure();
  // Binomial standard deviation sqrt(p(1-p)/n) ~ 0.0025; 6 sigma.
  CHECK(std::abs(static_cast<double>(inside_inner) / n - expected) < 6 * std::sqrt(expected * (1 - expected) / n));
}

TEST_CASE("The informed-set volume is (4/3) pi r1 r2^2 and degenerates to the segment", "[REQ-PLAN-002]") {
  const ProlateHyperspheroid ball_like(V(0, 0, 0), V(0, 0, 0), 2.0);  // coincident foci: ball of radius 1
  CHECK(ball_like.measure() == Approx(4.0 / 3.0 * M_PI));
  const ProlateHyperspheroid s(V(0, 0, 0), V(6, 0, 0), 10.0);  // r1 = 5, r2 = 4
  CHECK(s.measure() == Approx(4.0 / 3.0 * M_PI * 5 * 16));
  const ProlateHyperspheroid flat(V(0, 0, 0), V(6, 0, 0), 1.0);  // c below |b - a| is raised to it
  CHECK(flat.transverse_diameter() == 6.0);
  CHECK(flat.measure() == 0.0);
  miner::Rng rng(1);
  const V x = flat.sample(rng);
  CHECK(std::abs(x.y()) < 1e-12);
  CHECK(x.x() >= -1e-12);
  CHECK(x.x() <= 6 + 1e-12);
}
