#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

#include "miner/core/rng.hpp"
#include "miner/plan/informed_set.hpp"
#include "miner/testing/binomial.hpp"

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

TEST_CASE("Guided RRT*'s local subsets: the beacon's two sets, picked in proportion to their volumes", "[REQ-PLAN-003]") {
  // Start, goal, a beacon off the straight line on a solution of cost c_best, g the beacon's
  // cost-to-come: L_start has foci (start, b) and diameter g, L_goal foci (b, goal) and
  // c_best - g. Samples of the picked set lie in it; L_start is picked with probability
  // m_s / (m_s + m_g), checked against the exact binomial interval (false fail <= 1e-6): a
  // pick by count (1/2) or swapped (m_g share) misses it by tens of standard deviations.
  const V start(0, 0, 0), goal(10, 0, 0), beacon(4, 3, 0);
  const double g = 1.1 * (beacon - start).norm();
  const double c_best = g + 1.4 * (goal - beacon).norm();
  const miner::plan::GuidedLocalSubsets local(start, goal, beacon, g, c_best);
  REQUIRE(local.has_volume());
  CHECK(local.to_start().transverse_diameter() == Approx(g));
  CHECK(local.to_goal().transverse_diameter() == Approx(c_best - g));
  const double share = local.to_start().measure() / (local.to_start().measure() + local.to_goal().measure());
  CHECK(local.start_share() == Approx(share));
  REQUIRE(std::abs(share - 0.5) > 0.1);  // the two sets differ, so the proportion is tested
  miner::Rng rng(17);
  const int n = 20000;
  long from_start = 0;
  for (int i = 0; i < n; ++i) {
    const ProlateHyperspheroid& set = local.pick(rng);
    const V x = set.sample(rng);
    REQUIRE(set.contains(x));
    // In L_start: |x - start| + |x - b| <= g; in L_goal the other sum.
    if (&set == &local.to_start()) {
      ++from_start;
      CHECK((x - start).norm() + (x - beacon).norm() <= g * (1 + 1e-12));
    } else {
      CHECK((x - beacon).norm() + (x - goal).norm() <= (c_best - g) * (1 + 1e-12));
    }
  }
  const auto interval = miner::testing::binomial_interval(n, share, 1e-6);
  INFO("L_start picked " << from_start << " of " << n << ", expected share " << share);
  CHECK(from_start >= interval.lo);
  CHECK(from_start <= interval.hi);
  // A straight-line solution (beacon on the segment, g and c_best exact) has no volume.
  const miner::plan::GuidedLocalSubsets flat(start, goal, V(4, 0, 0), 4.0, 10.0);
  CHECK_FALSE(flat.has_volume());
}

TEST_CASE("Informed-set samples fill the set when the foci lie along a coordinate axis", "[REQ-PLAN-002][REQ-PLAN-003]") {
  // Held-out audit 8, h8-plan-04: the rotation's completion picked the focal axis itself when
  // it was a coordinate axis, and every sample fell on the segment between the foci.
  miner::Rng rng(11);
  for (int axis = 0; axis < 3; ++axis)
    for (const double sign : {1.0, -1.0}) {
      const V a(1, 2, 3);
      const V b = a + sign * 4.0 * V::Unit(axis);
      const double c = 5.0;  // r1 = 2.5, r2 = sqrt(25 - 16) / 2 = 1.5
      const ProlateHyperspheroid set(a, b, c);
      const ProlateHyperspheroid inner(a, b, 4.5);
      const int n = 20000;
      int inside_inner = 0;
      double widest = 0.0;
      for (int i = 0; i < n; ++i) {
        const V x = set.sample(rng);
        REQUIRE(set.contains(x));
        inside_inner += inner.contains(x);
        const V off = (x - a) - (x - a).dot(V::Unit(axis)) * V::Unit(axis);
        widest = std::max(widest, off.norm());
      }
      INFO("axis " << axis << ", sign " << sign);
      CHECK(widest > 0.9 * 1.5);  // the samples reach the transverse radius r2
      const double expected = inner.measure() / set.measure();
      CHECK(std::abs(static_cast<double>(inside_inner) / n - expected) < 6 * std::sqrt(expected * (1 - expected) / n));
    }
}

TEST_CASE("An informed set of non-finite foci or diameter is refused, not sampled as NaN", "[REQ-LIB-003][REQ-PLAN-002]") {
  using Catch::Matchers::Contains;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH(ProlateHyperspheroid(V(nan, 0, 0), V(1, 0, 0), 2.0), Contains("focus a"));
  CHECK_THROWS_WITH(ProlateHyperspheroid(V(0, 0, 0), V(1, 0, std::numeric_limits<double>::infinity()), 2.0), Contains("focus b"));
  CHECK_THROWS_WITH(ProlateHyperspheroid(V(0, 0, 0), V(1, 0, 0), nan), Contains("transverse diameter"));
}
