#include <catch2/catch.hpp>

#include <cmath>

#include "miner/core/error.hpp"
#include "miner/world/astar.hpp"
#include "miner/world/map.hpp"
#include "miner/world/voxel_grid.hpp"
#include "test_maps.hpp"

using miner::world::astar;
using miner::world::Box;
using miner::world::Map;
using miner::world::VoxelGrid;
using Catch::Matchers::Contains;
using V = Eigen::Vector3d;
using I = Eigen::Vector3i;

namespace {
// Path lengths are sums of at most a few hundred terms of size <= sqrt(3) res.
constexpr double kSumTolerance = 1e-12;
}  // namespace

TEST_CASE("In free space A* follows the octile distance between cell centres", "[REQ-WORLD-007]") {
  const Map map(Box{{0, 0, 0}, {10, 10, 10}}, 1.0, {});
  const VoxelGrid grid(map, 0.0);
  const auto path = astar(map, grid, V(0.5, 0.5, 0.5), V(9.5, 5.5, 2.5));
  // deltas (9, 5, 2): 2 sqrt3 + 3 sqrt2 + 4.
  const double expected = 2 * std::sqrt(3.0) + 3 * std::sqrt(2.0) + 4;
  CHECK(path.grid_cost == Approx(expected).margin(kSumTolerance));
  CHECK(path.cost == Approx(expected).margin(kSumTolerance));
  CHECK(path.cells.front() == I(0, 0, 0));
  CHECK(path.cells.back() == I(9, 5, 2));
  CHECK(path.cells.size() == 10);
  CHECK(path.points.front() == V(0.5, 0.5, 0.5));
  CHECK(path.points.back() == V(9.5, 5.5, 2.5));
  CHECK(miner::world::octile_distance(I(0, 0, 0), I(9, 5, 2), 1.0) == Approx(expected));
}

TEST_CASE("Start and goal in one cell: the straight segment; start == goal costs 0", "[REQ-WORLD-007]") {
  const Map map(Box{{0, 0, 0}, {10, 10, 10}}, 1.0, {});
  const VoxelGrid grid(map, 0.0);
  const auto same = astar(map, grid, V(3.2, 4.7, 5.1), V(3.2, 4.7, 5.1));
  CHECK(same.cost == 0.0);
  CHECK(same.points.size() == 2);
  const auto cell = astar(map, grid, V(3.2, 4.7, 5.1), V(3.9, 4.1, 5.8));
  CHECK(cell.cost == Approx((V(3.9, 4.1, 5.8) - V(3.2, 4.7, 5.1)).norm()).margin(kSumTolerance));
  CHECK(cell.grid_cost == 0.0);
}

TEST_CASE("A* goes through the only door of a wall and its path is collision-free", "[REQ-WORLD-007][REQ-WORLD-008]") {
  const Map map = miner::world::test::narrow_door_map();
  const VoxelGrid grid(map, 0.0);
  const auto path = astar(map, grid, V(1, 1, 0.5), V(9, 1, 0.5));
  bool through_door = false;
  for (const auto& p : path.points) through_door |= (p.x() > 4 && p.x() < 5 && p.y() > 8 && p.y() < 9);
  CHECK(through_door);
  for (std::size_t i = 1; i < path.points.size(); ++i) {
    INFO("segment " << i);
    CHECK(map.segment_free(path.points[i - 1], path.points[i]));
  }
  CHECK(path.cost > 2 * std::hypot(3.5, 7.5));  // at least the detour to the door and back
  CHECK(path.cost >= path.grid_cost - grid.resolution() * std::sqrt(3.0));
}

TEST_CASE("A diagonal move never cuts the corner of an occupied cell", "[REQ-WORLD-008]") {
  // Two boxes meeting at one edge x = y = 2: the diagonal (1.5,1.5) -> (2.5,2.5) would cut it,
  // so A* must walk around the pair: 6 straight moves instead of one diagonal of sqrt2.
  const Map map(Box{{0, 0, 0}, {4, 4, 1}}, 1.0, {Box{{1, 2, 0}, {2, 3, 1}}, Box{{2, 1, 0}, {3, 2, 1}}});
  const VoxelGrid grid(map, 0.0);
  const auto path = astar(map, grid, V(1.5, 1.5, 0.5), V(2.5, 2.5, 0.5));
  CHECK(path.grid_cost == Approx(6.0).margin(kSumTolerance));
  for (std::size_t i = 1; i < path.points.size(); ++i) {
    CHECK(map.segment_free(path.points[i - 1], path.points[i]));
  }
}

TEST_CASE("Start and goal errors name the point and what is wrong", "[REQ-WORLD-010]") {
  const Map map = miner::world::test::pillar_map();
  const VoxelGrid grid(map, 0.5);
  CHECK_THROWS_WITH(astar(map, grid, V(5, 5, 5), V(1, 1, 1)), Contains("start (5, 5, 5) lies inside obstacle 0"));
  CHECK_THROWS_WITH(astar(map, grid, V(1, 1, 1), V(20, 1, 1)), Contains("goal (20, 1, 1) lies outside the map bounds"));
  // Free in the continuous map (clearance 0.8 > 0.5) but its cell touches the inflated box.
  CHECK_THROWS_WITH(astar(map, grid, V(3.2, 5, 5), V(1, 1, 1)),
                    Contains("start (3.2, 5, 5) lies in an occupied grid cell (clearance 0.8"));
}

TEST_CASE("An unreachable goal is a NoSolution that says how much was searched", "[REQ-WORLD-010]") {
  // The goal sits in a closed room: a hollow box made of 6 walls.
  const Map map(Box{{0, 0, 0}, {10, 10, 10}}, 1.0,
                {Box{{6, 6, 6}, {9, 9, 7}}, Box{{6, 6, 8}, {9, 9, 9}}, Box{{6, 6, 7}, {7, 9, 8}},
                 Box{{8, 6, 7}, {9, 9, 8}}, Box{{7, 6, 7}, {8, 7, 8}}, Box{{7, 8, 7}, {8, 9, 8}}});
  const VoxelGrid grid(map, 0.0);
  try {
    astar(map, grid, V(1, 1, 1), V(7.5, 7.5, 7.5));
    FAIL("expected NoSolution");
  } catch (const miner::NoSolution& e) {
    CHECK_THAT(std::string(e.what()), Contains("goal (7.5, 7.5, 7.5) is unreachable from start (1, 1, 1)"));
    CHECK(e.code() == miner::ExitCode::kNoSolution);
  }
}
