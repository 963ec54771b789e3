#pragma once
/// \file
/// Seeded cluttered-map generator with the paper's presets (REQ-WORLD-009):
///  - "sim": the simulation maps of Sec. V-B, 100 x 100 x 40 m, cuboids with sides of
///    4-15 m, resolution 0.5 m, start and goal in opposite corners;
///  - "indoor": the real-flight site of Sec. V-D, 10 x 10 x 5 m, 15-20 cuboid pillars
///    with a 0.6 x 1.2 m footprint and a hoop of 1 m diameter, resolution 0.1 m.
/// Every generated map carries its query (start, goal, robot radius) and is checked to
/// be solvable by A* for that radius; the same (preset, seed) gives the same bytes.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "miner/world/map.hpp"

namespace miner::world {

struct GeneratorPreset {
  std::string name;
  Box bounds;
  double resolution;
  int min_obstacles, max_obstacles;  ///< obstacle count drawn uniformly in [min, max]
  double min_side, max_side;         ///< "sim": box sides drawn uniformly in [min, max]
  double robot_radius;               ///< radius the query is checked for
  double keep_free;                  ///< no obstacle within this distance of start/goal
  Box start_region, goal_region;     ///< where the query's start and goal are drawn
  double quantum;                    ///< coordinates are rounded to multiples of this
};

/// The named preset; throws miner::Error listing the known names otherwise.
GeneratorPreset generator_preset(const std::string& name);
std::vector<std::string> generator_preset_names();

/// Generates a map from `preset` and `seed`. `obstacle_count` overrides the preset's
/// range. Retries with the next stream of the seed (at most `kMaxAttempts`) until A*
/// finds the query's path; throws NoSolution if none of the attempts is solvable.
Map generate_map(const GeneratorPreset& preset, std::uint64_t seed,
                 std::optional<int> obstacle_count = std::nullopt);

inline constexpr int kMaxGeneratorAttempts = 16;

}  // namespace miner::world
