#pragma once
/// \file
/// Hand-made maps shared by the front-end unit and statistical tests (header-only; the
/// test must link miner_world).

#include "miner/world/map.hpp"

namespace miner::testing {

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

}  // namespace miner::testing
