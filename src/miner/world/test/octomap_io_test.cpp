#include <catch2/catch.hpp>

#include <fstream>

#include "miner/core/error.hpp"
#include "miner/world/map.hpp"
#include "test_maps.hpp"

using miner::world::Box;
using miner::world::Map;
using Catch::Matchers::Contains;
using V = Eigen::Vector3d;

TEST_CASE("A map survives a round trip through an OctoMap .bt file", "[REQ-WORLD-003]") {
  const Map map(Box{{0, 0, 0}, {4, 4, 2}}, 0.5, {Box{{1, 1, 0}, {2, 3, 1.5}}, Box{{3, 0, 0}, {3.5, 0.5, 0.5}}});
  const std::string path = miner::world::test::temp_path("roundtrip.bt");
  map.save(path);
  const Map back = Map::load(path);
  CHECK(back.resolution() == 0.5);
  // Every point strictly inside an original obstacle is inside an imported one.
  for (const Box& b : map.obstacles()) {
    for (double x = b.min.x() + 0.1; x < b.max.x(); x += 0.2)
      for (double y = b.min.y() + 0.1; y < b.max.y(); y += 0.2)
        for (double z = b.min.z() + 0.1; z < b.max.z(); z += 0.2) {
          INFO(miner::format_point(V(x, y, z)));
          CHECK(back.point_collision(V(x, y, z)));
        }
  }
  // Free space stays free, and the bounds cover the original ones.
  CHECK_FALSE(back.point_collision(V(0.25, 3.75, 1.75)));
  CHECK((back.bounds().min.array() <= map.bounds().min.array()).all());
  CHECK((back.bounds().max.array() >= map.bounds().max.array()).all());
}

TEST_CASE("Unreadable OctoMap files are refused by name", "[REQ-WORLD-003]") {
  CHECK_THROWS_WITH(Map::load(miner::world::test::temp_path("missing.bt")), Contains("missing.bt: cannot open file"));
  const std::string garbage = miner::world::test::temp_path("garbage.bt");
  std::ofstream(garbage) << "this is not an octree\n";
  CHECK_THROWS_WITH(Map::load(garbage), Contains("garbage.bt: not a readable OctoMap binary tree"));
}
