#pragma once
// Small hand-made maps shared by the world tests.
#include <filesystem>
#include <string>

#include "miner/world/map.hpp"

namespace miner::world::test {

/// 10 x 10 x 10 m, resolution 1, one box [4,6] x [4,6] x [0,10] (a pillar through the map).
inline Map pillar_map() {
  return Map(Box{{0, 0, 0}, {10, 10, 10}}, 1.0, {Box{{4, 4, 0}, {6, 6, 10}}});
}

/// A wall x in [4, 5] closing the whole map except a 1 m door at y in [8, 9], z in [0, 1]
/// (narrower than testing::wall_with_door_map()'s 1.5 x 1.5 m door, for the A* grid tests).
inline Map narrow_door_map() {
  return Map(Box{{0, 0, 0}, {10, 10, 3}}, 0.5,
             {Box{{4, 0, 0}, {5, 8, 3}}, Box{{4, 9, 0}, {5, 10, 3}}, Box{{4, 8, 1}, {5, 9, 3}}});
}

inline std::string temp_path(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / "miner_world_test";
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

}  // namespace miner::world::test
