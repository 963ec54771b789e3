// The "scan" map family (REQ-WORLD-019): the voxel map a mapping run leaves behind. A map of
// another family is drawn first (the world as it is); a range sensor is flown through it on a
// tour from the query's start through random waypoints to its goal (scan_map, REQ-WORLD-016),
// with a sensor, range, noise and dropout drawn per map; the result is that run's OctoMap:
// free where rays passed, occupied where they ended, unknown everywhere else (read as
// occupied), bounded by what the run saw. The planner and the sGAN then see only the scan.
#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "miner/core/error.hpp"
#include "miner/core/rng.hpp"
#include "miner/world/astar.hpp"
#include "miner/world/map_generator.hpp"
#include "miner/world/scan.hpp"
#include "miner/world/voxel_grid.hpp"

namespace miner::world {

namespace {

/// The worlds a mapping run is drawn over: every other generated preset.
const std::array<const char*, 6> kScanBases{"cluttered", "rooms", "forest", "multilevel", "sim", "indoor"};

/// The scan's own streams (mixed, so no retry of one seed is the first try of another).
constexpr std::uint64_t kScanStream = 0x5ca11ULL;

/// Waypoints the tour visits between start and goal, drawn uniformly in [0, kMaxWaypoints]:
/// a mapping run explores more than the one corridor a planner would fly.
constexpr int kMaxWaypoints = 3;
/// Draws per waypoint before it is skipped (a free, A*-reachable point).
constexpr int kWaypointDraws = 32;

/// The sensor of one mapping run, drawn per map. Ranges scale with the map's horizontal
/// size (a 10 m room is scanned with a short range, a 150 m forest with a long one) within
/// what such sensors give: depth cameras 3-10 m, lidars 5-30 m. Noise is up to half a voxel
/// (below that a return lands in the right voxel most of the time), dropout up to 5 %.
ScanOptions draw_sensor(Rng& rng, const Box& bounds, double resolution, double body_radius, std::uint64_t seed) {
  ScanOptions s;
  const double size = std::hypot(bounds.extent().x(), bounds.extent().y());
  if (rng.uniform01() < 0.6) {  // spinning lidar
    s.h_fov_deg = 360.0;
    s.v_fov_deg = rng.uniform(30.0, 45.0);
    s.h_rays = 180;
    s.v_rays = 16;
    s.range = std::clamp(rng.uniform(0.15, 0.3) * size, 5.0, 30.0);
  } else {  // forward depth camera
    s.h_fov_deg = rng.uniform(70.0, 90.0);
    s.v_fov_deg = rng.uniform(45.0, 60.0);
    s.h_rays = 64;
    s.v_rays = 48;
    s.range = std::clamp(rng.uniform(0.1, 0.2) * size, 3.0, 10.0);
  }
  s.noise = rng.uniform(0.0, 0.5) * resolution;
  s.dropout = rng.uniform(0.0, 0.05);
  // Poses a quarter of the range apart (every surface seen from several poses), no closer
  // than two voxels.
  s.spacing = std::max(0.25 * s.range, 2.0 * resolution);
  s.resolution = resolution;
  s.body_radius = body_radius;
  s.spin_at_ends = true;
  s.seed = seed;
  return s;
}

/// The tour: A* from the start through the waypoints that could be reached to the goal.
std::vector<Eigen::Vector3d> mapping_tour(Rng& rng, const Map& map, const Query& q) {
  const VoxelGrid grid(map, q.robot_radius);
  const Box& b = map.bounds();
  const double r = q.robot_radius;
  std::vector<Eigen::Vector3d> tour{q.start};
  const auto leg = [&](const Eigen::Vector3d& to) {
    const GridPath path = astar(map, grid, tour.back(), to);
    tour.insert(tour.end(), path.points.begin() + 1, path.points.end());
  };
  const int waypoints = static_cast<int>(rng.uniform_index(kMaxWaypoints + 1));
  for (int w = 0; w < waypoints; ++w) {
    for (int draw = 0; draw < kWaypointDraws; ++draw) {
      Eigen::Vector3d p;
      for (int k = 0; k < 3; ++k) p[k] = rng.uniform(b.min[k] + r, b.max[k] - r);
      if (!map.is_free(p, r)) continue;
      try {
        leg(p);
        break;
      } catch (const Error&) {
        // unreachable from here: draw again
      }
    }
  }
  leg(q.goal);  // the base map's query is solvable by construction
  return tour;
}

}  // namespace

std::vector<std::string> scan_base_names() { return {kScanBases.begin(), kScanBases.end()}; }

ScanMap generate_scan_map(const GeneratorPreset& preset, std::uint64_t seed, const GeneratorOverrides& overrides) {
  check_overrides(preset, overrides);
  GeneratorOverrides base_overrides = overrides;
  base_overrides.base.reset();
  for (int attempt = 0; attempt < kMaxGeneratorAttempts; ++attempt) {
    Rng rng(seed, splitmix64(kScanStream + static_cast<std::uint64_t>(attempt)));  // apart from the base's streams
    std::string base_name;
    if (overrides.base) {
      base_name = *overrides.base;
    } else {
      // With a size or resolution override only the families (which take them) are drawn.
      const std::size_t choices = overrides.size || overrides.resolution ? 4 : kScanBases.size();
      base_name = kScanBases[rng.uniform_index(choices)];
    }
    const GeneratorPreset base_preset = generator_preset(base_name);
    // The base's own failure names the scan's seed, the one the user gave (issue 20, eighth
    // campaign U3: it named the internal base seed, which the user cannot pass back).
    const std::uint64_t base_seed = rng.next_u64();
    Map base = [&] {
      try {
        return generate_map(base_preset, base_seed, base_overrides);
      } catch (const NoSolution&) {
        throw NoSolution("preset \"scan\", seed " + std::to_string(seed) + ": its base map \"" + base_name +
                         "\" has no solvable draw with these overrides in " + std::to_string(kMaxGeneratorAttempts) +
                         " attempts (too many obstacles for its size?)");
      }
    }();
    // Every scan is planned for the preset's radius, the smallest of the bases' (so the base
    // map's own query, checked for a radius at least as large, stays solvable in it).
    const Query query{base.query()->start, base.query()->goal, preset.robot_radius};
    const std::vector<Eigen::Vector3d> tour = mapping_tour(rng, base, query);
    const ScanOptions sensor = draw_sensor(rng, base.bounds(), base.resolution(), query.robot_radius, rng.next_u64());
    const ScanResult scan = scan_map(base, tour, sensor);
    const std::shared_ptr<const VoxelLayer> layer = scan.layer;
    try {
      Map scanned(layer->bounds(), layer->resolution(), {}, query, VoxelSource{layer, UnknownPolicy::kOccupied, "", ""});
      scanned.require_free(query.start, query.robot_radius, "start");
      scanned.require_free(query.goal, query.robot_radius, "goal");
      const VoxelGrid grid(scanned, query.robot_radius);
      astar(scanned, grid, query.start, query.goal);
      return {std::move(scanned), base_name, sensor};
    } catch (const Error&) {
      continue;  // a noisy return closed the route: draw the next attempt
    }
  }
  throw NoSolution("preset \"scan\": no solvable scan in " + std::to_string(kMaxGeneratorAttempts) +
                   " attempts for seed " + std::to_string(seed) +
                   " (at a coarse resolution a scan's voxels close narrow doors and gaps: try a finer --resolution or "
                   "a larger --size)");
}

}  // namespace miner::world
