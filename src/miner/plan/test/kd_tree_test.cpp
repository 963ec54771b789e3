#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

#include "miner/core/error.hpp"
#include "miner/core/rng.hpp"
#include "miner/plan/kd_tree.hpp"

using miner::plan::KdTree;
using V = Eigen::Vector3d;

TEST_CASE("The k-d tree answers nearest and radius queries like a linear scan", "[REQ-PLAN-006]") {
  miner::Rng rng(7);
  KdTree tree;
  std::vector<V> points;
  for (int i = 0; i < 2000; ++i) {
    // Coarse coordinates make exact ties (equal distances, equal split values) common.
    const V p(std::floor(rng.uniform(0, 20)), std::floor(rng.uniform(0, 20)), std::floor(rng.uniform(0, 5)));
    CHECK(tree.insert(p) == points.size());
    points.push_back(p);
  }
  std::vector<std::size_t> got;
  for (int q = 0; q < 300; ++q) {
    const V x(rng.uniform(-2, 22), rng.uniform(-2, 22), rng.uniform(-2, 7));
    std::size_t best = 0;
    for (std::size_t i = 1; i < points.size(); ++i) {
      if ((points[i] - x).squaredNorm() < (points[best] - x).squaredNorm()) best = i;
    }
    REQUIRE(tree.nearest(x) == best);
    const double r = rng.uniform(0, 3);
    std::vector<std::size_t> expected;
    for (std::size_t i = 0; i < points.size(); ++i) {
      if ((points[i] - x).norm() <= r) expected.push_back(i);
    }
    tree.within(x, r, got);
    REQUIRE(got == expected);
  }
}

TEST_CASE("An empty k-d tree refuses nearest and returns no neighbours", "[REQ-PLAN-006]") {
  KdTree tree;
  CHECK(tree.empty());
  CHECK_THROWS_AS(tree.nearest(V::Zero()), miner::Error);
  std::vector<std::size_t> out{1, 2};
  tree.within(V::Zero(), 1.0, out);
  CHECK(out.empty());
  tree.insert(V(1, 1, 1));
  tree.within(V::Zero(), -1.0, out);  // a negative radius holds nothing
  CHECK(out.empty());
  CHECK(tree.nearest(V(5, 5, 5)) == 0);
}

TEST_CASE("A radius query returns the closed ball: points exactly at distance r are included", "[REQ-PLAN-006]") {
  // Integer coordinates and radii: every squared distance and r^2 is exact, so the points on
  // the sphere |p - q| = r (axis offsets, the 3-4-5 and 1-2-2 triangles, 2-3-6 of 7) are on
  // it exactly and must be returned, as a linear scan with <= returns them.
  miner::Rng rng(26);
  KdTree tree;
  std::vector<V> points;
  for (int x = -7; x <= 7; ++x)
    for (int y = -7; y <= 7; ++y)
      for (int z = -7; z <= 7; ++z) {
        const V p(x, y, z);
        tree.insert(p);
        points.push_back(p);
      }
  // The tree built in random order too (its splits then fall elsewhere).
  std::vector<std::size_t> order(points.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  for (std::size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[rng.uniform_index(i)]);
  KdTree shuffled;
  for (std::size_t i : order) shuffled.insert(points[i]);

  std::vector<std::size_t> got, expected;
  for (double r : {0.0, 1.0, 2.0, 3.0, 5.0, 7.0}) {
    for (int trial = 0; trial < 20; ++trial) {
      const V q(static_cast<double>(rng.uniform_index(9)) - 4.0, static_cast<double>(rng.uniform_index(9)) - 4.0,
                static_cast<double>(rng.uniform_index(9)) - 4.0);
      expected.clear();
      std::size_t on_sphere = 0;
      for (std::size_t i = 0; i < points.size(); ++i) {
        const double d2 = (points[i] - q).squaredNorm();
        if (d2 <= r * r) expected.push_back(i);
        if (d2 == r * r) ++on_sphere;
      }
      INFO("r = " << r << ", q = " << q.transpose());
      REQUIRE(on_sphere > 0);  // the query has points exactly at distance r
      tree.within(q, r, got);
      CHECK(got == expected);
      shuffled.within(q, r, got);
      std::vector<std::size_t> mapped;
      for (std::size_t j : got) mapped.push_back(order[j]);
      std::sort(mapped.begin(), mapped.end());
      CHECK(mapped == expected);
    }
  }
  // The named offsets themselves.
  tree.within(V::Zero(), 5.0, got);
  const auto has = [&](const V& p) {
    for (std::size_t i : got)
      if (points[i] == p) return true;
    return false;
  };
  CHECK(has(V(3, 4, 0)));
  CHECK(has(V(0, -4, 3)));
  CHECK(has(V(5, 0, 0)));
  CHECK(has(V(0, 0, -5)));
  CHECK_FALSE(has(V(3, 4, 1)));
  tree.within(V::Zero(), 3.0, got);
  CHECK(has(V(1, 2, 2)));
  CHECK(has(V(-2, 1, -2)));
}

TEST_CASE("Points equal to a split go to both sides in turn: duplicates make a shallow tree and exact answers",
          "[REQ-PLAN-006][REQ-LIB-003]") {
  // Tenth campaign L14: equal coordinates all went to the >= side, so 10^5 copies of one point
  // made a chain 10^5 deep (insertion quadratic, over 20 s).
  KdTree same;
  const int n = 1 << 14;
  for (int i = 0; i < n; ++i) same.insert(V(1, 1, 1));
  CHECK(same.height() <= 2 * 14 + 2);  // a chain would be 16384
  CHECK(same.nearest(V(1, 1, 1)) == 0);
  CHECK(same.nearest(V(5, 5, 5)) == 0);
  std::vector<std::size_t> out;
  same.within(V(1, 1, 1), 0.0, out);
  CHECK(out.size() == static_cast<std::size_t>(n));
  // Duplicates and ties on one axis mixed with random points: the answers are a linear scan's,
  // the closed ball on both sides of every split (points equal to a split sit on either side).
  miner::Rng rng(13);
  KdTree tree;
  std::vector<V> points;
  for (int i = 0; i < 3000; ++i) {
    const double u = rng.uniform01();
    const V p = u < 0.3 ? V(2, 2, 2)
                : u < 0.6 ? V(std::round(4 * rng.uniform01()) / 2, 2, std::round(4 * rng.uniform01()) / 2)
                          : V(4 * rng.uniform01(), 4 * rng.uniform01(), 4 * rng.uniform01());
    tree.insert(p);
    points.push_back(p);
  }
  CHECK(tree.height() < 200);
  for (int k = 0; k < 300; ++k) {
    const V q = k % 3 == 0 ? V(2, 2, 2) : k % 3 == 1 ? V(std::round(4 * rng.uniform01()) / 2, 2, 1.5)
                                                  : V(4 * rng.uniform01(), 4 * rng.uniform01(), 4 * rng.uniform01());
    std::size_t best = 0;
    for (std::size_t i = 1; i < points.size(); ++i)
      if ((points[i] - q).squaredNorm() < (points[best] - q).squaredNorm()) best = i;
    CHECK(tree.nearest(q) == best);
    const double r = k % 2 == 0 ? 0.5 : 0.0;
    std::vector<std::size_t> expected;
    for (std::size_t i = 0; i < points.size(); ++i)
      if ((points[i] - q).squaredNorm() <= r * r) expected.push_back(i);
    tree.within(q, r, out);
    CHECK(out == expected);
  }
}
