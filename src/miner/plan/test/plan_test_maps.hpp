#pragma once
// Small maps shared by the plan tests.
#include <filesystem>
#include <string>

#include <unistd.h>

#include "miner/world/map.hpp"

namespace miner::plan::test {

/// 10 x 10 x 3 m; a wall x in [4, 5] closes the map except a door y in [7.5, 9], z in [0, 1.5]
/// (wide enough that the conservative A* grid at 0.5 m keeps it open for a 0.1 m robot).
inline world::Map wall_with_door_map() {
  using world::Box;
  return world::Map(Box{{0, 0, 0}, {10, 10, 3}}, 0.5,
                    {Box{{4, 0, 0}, {5, 7.5, 3}}, Box{{4, 9, 0}, {5, 10, 3}}, Box{{4, 7.5, 1.5}, {5, 9, 3}}});
}

/// The same wall with no door: x_goal on the other side is unreachable.
inline world::Map closed_wall_map() {
  using world::Box;
  return world::Map(Box{{0, 0, 0}, {10, 10, 3}}, 0.5, {Box{{4, 0, 0}, {5, 10, 3}}});
}

/// A per-process temp folder (ctest runs the cases of one binary in parallel).
inline std::string temp_path(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("miner_plan_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

}  // namespace miner::plan::test
