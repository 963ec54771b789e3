#include <catch2/catch.hpp>

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
