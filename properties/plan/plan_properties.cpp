// Properties of the front end (spec/plan.md), checked by rapidcheck on random point sets,
// regions and maps built from a generated seed through the project's Rng.
#include <catch2/catch.hpp>

#include "miner/core/error.hpp"
#include "miner/core/rng.hpp"
#include "miner/plan/heuristic_region.hpp"
#include "miner/plan/informed_set.hpp"
#include "miner/plan/kd_tree.hpp"
#include "miner/plan/reference.hpp"
#include "miner/plan/rrt_star.hpp"
#include "miner/testing/property.hpp"
#include "miner/world/map.hpp"

using miner::Rng;
using miner::testing::property;
using miner::world::Box;
using V = Eigen::Vector3d;
using I = Eigen::Vector3i;

TEST_CASE("k-d tree queries equal a linear scan on random point sets", "[REQ-PLAN-006]") {
  property("nearest and within equal the scan", [](std::uint64_t seed) {
    Rng rng(seed);
    miner::plan::KdTree tree;
    std::vector<V> pts;
    const auto n = 1 + rng.uniform_index(400);
    for (std::uint64_t i = 0; i < n; ++i) {
      pts.emplace_back(rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-5, 5));
      tree.insert(pts.back());
    }
    std::vector<std::size_t> got, want;
    for (int q = 0; q < 20; ++q) {
      const V x(rng.uniform(-6, 6), rng.uniform(-6, 6), rng.uniform(-6, 6));
      std::size_t best = 0;
      for (std::size_t i = 1; i < pts.size(); ++i) {
        if ((pts[i] - x).squaredNorm() < (pts[best] - x).squaredNorm()) best = i;
      }
      RC_ASSERT(tree.nearest(x) == best);
      const double r = rng.uniform(0, 4);
      want.clear();
      for (std::size_t i = 0; i < pts.size(); ++i) {
        if ((pts[i] - x).norm() <= r) want.push_back(i);
      }
      tree.within(x, r, got);
      RC_ASSERT(got == want);
    }
  });
}

TEST_CASE("Informed-set and region samples stay inside their sets", "[REQ-PLAN-002][REQ-PLAN-004]") {
  property("samples are members", [](std::uint64_t seed) {
    Rng rng(seed);
    const V a(rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-5, 5));
    const V b(rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-5, 5));
    const miner::plan::ProlateHyperspheroid set(a, b, (b - a).norm() * rng.uniform(1.0, 3.0) + 1e-3);
    for (int i = 0; i < 50; ++i) RC_ASSERT(set.contains(set.sample(rng)));
    const I dims(1 + static_cast<int>(rng.uniform_index(8)), 1 + static_cast<int>(rng.uniform_index(8)),
                 1 + static_cast<int>(rng.uniform_index(4)));
    std::vector<double> p(static_cast<std::size_t>(dims.prod()));
    for (double& v : p) v = rng.uniform01();
    p[rng.uniform_index(p.size())] = 1.0;  // H is never empty
    const miner::plan::HeuristicRegion region(Box{{-1, 0, 2}, {7, 3, 5}}, dims, p, 0.5);
    for (int i = 0; i < 50; ++i) RC_ASSERT(region.contains(region.sample(rng)));
  });
}

TEST_CASE("On random maps every planner's path is collision-free and no shorter than the straight line", "[REQ-PLAN-001][REQ-PLAN-009]") {
  property("paths are valid", [](std::uint64_t seed) {
    Rng rng(seed);
    std::vector<Box> boxes;
    const auto n = rng.uniform_index(10);
    for (std::uint64_t i = 0; i < n; ++i) {
      const V lo(rng.uniform(0, 9), rng.uniform(0, 9), rng.uniform(0, 4));
      boxes.push_back({lo, lo + V(rng.uniform(0.2, 3), rng.uniform(0.2, 3), rng.uniform(0.2, 3))});
    }
    const miner::world::Map map(Box{{0, 0, 0}, {10, 10, 5}}, 0.5, boxes);
    const double radius = 0.1;
    const V start(rng.uniform(0, 10), rng.uniform(0, 10), rng.uniform(0, 5));
    const V goal(rng.uniform(0, 10), rng.uniform(0, 10), rng.uniform(0, 5));
    RC_PRE(map.is_free(start, radius) && map.is_free(goal, radius));
    const auto problem = miner::plan::PlanningProblem::make(map, start, goal, radius);
    const miner::plan::HeuristicRegion region(map.bounds(), I(5, 5, 5), std::vector<double>(125, 1.0), 0.5);
    for (miner::plan::PlannerKind kind : miner::plan::all_planners()) {
      miner::plan::PlannerOptions o;
      o.planner = kind;
      o.seed = seed;
      o.max_iterations = 400;
      const auto r = miner::plan::plan(problem, o, &region);
      if (!r.solved) continue;
      RC_ASSERT(r.path.front() == start);
      RC_ASSERT(r.path.back() == goal);
      for (std::size_t i = 1; i < r.path.size(); ++i) RC_ASSERT(map.segment_free(r.path[i - 1], r.path[i], radius));
      RC_ASSERT(r.cost >= miner::plan::straight_line_bound(problem) - 1e-9);
    }
  });
}
