#pragma once
/// \file
/// Seeded map generator. The paper's presets (REQ-WORLD-009):
///  - "sim": the simulation maps of Sec. V-B, 100 x 100 x 40 m, cuboids with sides of
///    4-15 m, resolution 0.5 m, start and goal in opposite corners;
///  - "indoor": the real-flight site of Sec. V-D, 10 x 10 x 5 m, 15-20 cuboid pillars
///    with a 0.6 x 1.2 m footprint and a hoop of 1 m diameter, resolution 0.1 m.
/// Map families beyond the paper (REQ-WORLD-011), each drawing its extents and
/// resolution per map so a family spans sizes and aspect ratios (map_families.cpp):
///  - "cluttered": 10-60 m, dense cuboids with sides 5-20 % of the map's size;
///  - "rooms": an office floor (20-60 x 15-40 x 3-4.5 m): a corridor, rooms behind
///    walls with doors, furniture;
///  - "forest": 20-150 m, thin trunks (0.2-0.6 m) with branches, 3-9 per 100 m^2;
///  - "multilevel": 2-4 storeys of slabs with stair/atrium openings, bridges across
///    them, overhangs, partition walls and a roof, start on the ground floor and goal
///    on the top one;
///  - "mixed" (REQ-WORLD-020): 8-100 x 8-100 x 3-40 m, the families' parts at random:
///    slabs across any axis with openings, free boxes, pillars and beams (domain
///    randomisation for the learned heuristic).
/// And "scan" (REQ-WORLD-019, scan_family.cpp): the voxel map a simulated mapping run
/// leaves over a map of another preset (free, occupied, unknown; bounded by what it saw).
/// Every generated map carries its query (start, goal, robot radius) and is checked to
/// be solvable by A* for that radius; the same (preset, seed, overrides) gives the same bytes.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "miner/core/rng.hpp"
#include "miner/world/map.hpp"
#include "miner/world/scan.hpp"

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
  /// Families (REQ-WORLD-011): extents drawn per map, uniformly in [min_extent, max_extent]
  /// (bounds.max is max_extent); unused (zero) for "sim" and "indoor", whose bounds are fixed.
  Eigen::Vector3d min_extent = Eigen::Vector3d::Zero();
  /// Families: the resolution is the finest of these giving at most kMaxFamilyCells per axis.
  std::vector<double> resolutions;
};

/// Overrides of what a preset would draw (`miner map gen --size/--resolution/--obstacles`):
/// a held-out benchmark map of another size is the same family at another extent.
struct GeneratorOverrides {
  std::optional<int> obstacles;           ///< count (sim, indoor, cluttered, forest trunks)
  std::optional<Eigen::Vector3d> size;    ///< extents in m (families only)
  std::optional<double> resolution;       ///< m (families only)
  std::optional<std::string> base;        ///< "scan": the preset the mapping run flies over
};

/// Largest grid axis a family map gets when its resolution is drawn (A* and the
/// voxel grid stay within ~10^7 cells).
inline constexpr double kMaxFamilyCells = 300.0;

/// Throws miner::Error unless `overrides` suit `preset`: each message starts with the
/// override's name as `miner map gen` spells its option without the dashes ("base: ...",
/// "size: ...", "resolution: ...", "obstacles: ..."), so the command line reports it as a
/// usage error before any work. generate_map checks the same.
void check_overrides(const GeneratorPreset& preset, const GeneratorOverrides& overrides);
/// The presets a "scan" map may fly over (`--base`).
std::vector<std::string> scan_base_names();

/// The named preset; throws miner::Error listing the known names otherwise.
GeneratorPreset generator_preset(const std::string& name);
std::vector<std::string> generator_preset_names();

/// Generates a map from `preset` and `seed`. `obstacle_count` overrides the preset's
/// range. Retries with the next stream of the seed (at most `kMaxAttempts`) until A*
/// finds the query's path; throws NoSolution if none of the attempts is solvable.
Map generate_map(const GeneratorPreset& preset, std::uint64_t seed,
                 std::optional<int> obstacle_count = std::nullopt);
Map generate_map(const GeneratorPreset& preset, std::uint64_t seed, const GeneratorOverrides& overrides);

/// One "scan" map (REQ-WORLD-019) and how it was made.
struct ScanMap {
  Map map;                ///< the run's voxels alone, with the base map's query at the preset's radius
  std::string base;       ///< the preset the run flew over
  ScanOptions sensor;     ///< the sensor drawn for it
};
/// The "scan" preset's map for `seed` (generate_map returns its `map`); throws NoSolution when
/// no attempt leaves a solvable query, miner::Error naming a bad override.
ScanMap generate_scan_map(const GeneratorPreset& preset, std::uint64_t seed, const GeneratorOverrides& overrides);

/// Whether the preset is one of the REQ-WORLD-011 families (extents drawn per map).
bool is_family(const GeneratorPreset& preset);

namespace detail {
/// One family map's obstacles and query for the given bounds and resolution (map_families.cpp).
struct FamilyDraw {
  std::vector<Box> obstacles;
  Query query;
};
FamilyDraw draw_family(const GeneratorPreset& preset, Rng& rng, const Box& bounds,
                       std::optional<int> obstacles);
/// Boxes covering the rectangle [u0, u1] x [v0, v1] of the plane across `axis` (u and v the
/// next two axes in turn), [w0, w1] thick along it, less the `openings` (boxes whose extent
/// in u and v cuts the plane; their extent along `axis` is ignored): "mixed"'s slabs.
void slab_with_openings(std::vector<Box>& out, int axis, double w0, double w1, double u0, double u1, double v0,
                        double v1, const std::vector<Box>& openings);
/// The 1-3 openings of one "mixed" slab across `axis` centred at w, t thick, drawn from `rng`
/// within `bounds` (boxes 2 t long along `axis`, corners rounded to the 0.05 m quantum): the
/// first at least 2 r + 0.3 m on each of the plane's axes before rounding (r the preset's
/// robot radius), the others at least 0.2 m (REQ-WORLD-020).
std::vector<Box> slab_openings(const GeneratorPreset& preset, Rng& rng, const Box& bounds, int axis, double w,
                               double t);

}  // namespace detail

inline constexpr int kMaxGeneratorAttempts = 16;

}  // namespace miner::world
