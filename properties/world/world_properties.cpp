// Properties of the world model (spec/world.md), checked by rapidcheck on random
// boxes, segments and maps. Each random scene is built from a generated 64-bit seed
// through the project's Rng, so a failure prints a seed that rebuilds the scene.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <optional>
#include <queue>

#include "miner/core/error.hpp"
#include "miner/core/rng.hpp"
#include "miner/testing/property.hpp"
#include "miner/world/astar.hpp"
#include "miner/world/map.hpp"
#include "miner/world/map_generator.hpp"
#include "miner/world/octree_io.hpp"
#include "miner/core/json_io.hpp"
#include "miner/world/voxel_grid.hpp"

using namespace miner::world;
using miner::Rng;
using miner::testing::property;
using V = Eigen::Vector3d;

namespace {

/// Rounding slack on squared distances of points within ~20 m: a few ulps of 400.
constexpr double kDistanceRounding = 1e-12;

/// A generated map's query: start and goal free for its radius, and an A* path whose every
/// segment is collision-free in the continuous map (REQ-WORLD-011, REQ-WORLD-019).
void rc_assert_query_solvable(const Map& map) {
  const Query& q = *map.query();
  RC_ASSERT(map.is_free(q.start, q.robot_radius));
  RC_ASSERT(map.is_free(q.goal, q.robot_radius));
  const VoxelGrid grid(map, q.robot_radius);
  const GridPath path = astar(map, grid, q.start, q.goal);
  for (std::size_t i = 1; i < path.points.size(); ++i)
    RC_ASSERT(map.segment_free(path.points[i - 1], path.points[i], q.robot_radius));
}

/// A size near a family's smallest extents (small maps keep a case cheap; the generator's
/// logic is the same at every size).
V small_family_size(Rng& rng, const GeneratorPreset& p) {
  V size;
  for (int k = 0; k < 3; ++k) size[k] = std::round(rng.uniform(p.min_extent[k], 1.1 * p.min_extent[k]));
  return size;
}

Box random_box(Rng& rng, double lo, double hi, double max_side) {
  V a(rng.uniform(lo, hi), rng.uniform(lo, hi), rng.uniform(lo, hi));
  V s(rng.uniform(0.05, max_side), rng.uniform(0.05, max_side), rng.uniform(0.05, max_side));
  return {a, a + s};
}

V random_point(Rng& rng, const Box& b) {
  return {rng.uniform(b.min.x(), b.max.x()), rng.uniform(b.min.y(), b.max.y()),
          rng.uniform(b.min.z(), b.max.z())};
}

/// A random map of up to 12 boxes in [0, 10]^3 at resolution 0.5 or 1.
Map random_box_map(Rng& rng) {
  std::vector<Box> boxes;
  const int n = static_cast<int>(rng.uniform_index(13));
  for (int i = 0; i < n; ++i) boxes.push_back(random_box(rng, -1.0, 10.0, 4.0));
  return Map(Box{{0, 0, 0}, {10, 10, 10}}, rng.uniform01() < 0.5 ? 0.5 : 1.0, std::move(boxes));
}

/// A random voxel layer on the lattice of `res` overlapping [0, 10]^3 (partly outside it at
/// times), or with `cover` holding all of it (a map whose unknown space is occupied must not
/// reach beyond its voxels, REQ-WORLD-013): free background, occupied and unknown blocks,
/// scattered single voxels.
std::shared_ptr<const VoxelLayer> random_layer(Rng& rng, double res, bool cover = false) {
  const int side = static_cast<int>(std::round(10.0 / res));
  Eigen::Vector3i origin, dims;
  for (int k = 0; k < 3; ++k) {
    if (cover) {
      origin[k] = -static_cast<int>(rng.uniform_index(3));
      dims[k] = side - origin[k] + static_cast<int>(rng.uniform_index(3));
      continue;
    }
    origin[k] = static_cast<int>(rng.uniform_index(side / 2 + 3)) - 2;
    dims[k] = 1 + static_cast<int>(rng.uniform_index(side));
  }
  std::vector<std::uint8_t> states(static_cast<std::size_t>(dims.prod()), 0);
  const auto block = [&](std::uint8_t state, int max_side) {
    Eigen::Vector3i lo, hi;
    for (int k = 0; k < 3; ++k) {
      lo[k] = static_cast<int>(rng.uniform_index(dims[k]));
      hi[k] = std::min(dims[k], lo[k] + 1 + static_cast<int>(rng.uniform_index(max_side)));
    }
    for (int z = lo.z(); z < hi.z(); ++z)
      for (int y = lo.y(); y < hi.y(); ++y)
        for (int x = lo.x(); x < hi.x(); ++x) states[(static_cast<std::size_t>(z) * dims.y() + y) * dims.x() + x] = state;
  };
  const int blocks = static_cast<int>(rng.uniform_index(6));
  for (int b = 0; b < blocks; ++b) block(rng.uniform01() < 0.7 ? 1 : 2, 6);
  const int singles = static_cast<int>(rng.uniform_index(20));
  for (int b = 0; b < singles; ++b) block(rng.uniform01() < 0.7 ? 1 : 2, 1);
  return std::make_shared<const VoxelLayer>(origin, res, dims, std::move(states));
}

/// A box map, half the time with a voxel layer under a random unknown-space policy.
Map random_map(Rng& rng) {
  const Map boxes = random_box_map(rng);
  if (rng.uniform01() < 0.5) return boxes;
  const UnknownPolicy policy = rng.uniform01() < 0.5 ? UnknownPolicy::kOccupied : UnknownPolicy::kFree;
  VoxelSource source{random_layer(rng, boxes.resolution(), policy == UnknownPolicy::kOccupied), policy, "", ""};
  return Map(boxes.bounds(), boxes.resolution(), boxes.obstacles(), std::nullopt, std::move(source));
}

/// Every obstacle as a box: the boxes and the cubes of the blocked voxels (for brute force).
std::vector<Box> all_obstacles(const Map& map) {
  std::vector<Box> out = map.obstacles();
  if (const VoxelObstacles* v = map.voxels()) {
    for (std::size_t i = 0; i < v->layer().size(); ++i)
      if (v->blocked(i)) out.push_back(v->layer().cell_box(v->layer().coords(i)));
  }
  return out;
}

/// Point, segment and clearance answers of `map` at p, [p, q] with radius r equal a brute force
/// over `obstacles` (every box and blocked voxel cube).
void check_queries(const Map& map, const std::vector<Box>& obstacles, const V& p, const V& q, double r) {
  double dp = std::numeric_limits<double>::infinity(), ds = dp;
  for (const Box& b : obstacles) {
    dp = std::min(dp, squared_distance(p, b));
    ds = std::min(ds, squared_distance(p, q, b));
  }
  RC_ASSERT(map.point_collision(p, r).has_value() == (dp <= r * r));
  RC_ASSERT(map.segment_collision(p, q, r).has_value() == (ds <= r * r));
  RC_ASSERT(std::fabs(map.clearance(p) - std::sqrt(dp)) <= kDistanceRounding || obstacles.empty());
}

/// Dijkstra with the same moves and corner rule as astar(), written independently.
double dijkstra_grid_cost(const VoxelGrid& grid, const Eigen::Vector3i& s, const Eigen::Vector3i& g) {
  std::vector<double> dist(grid.cell_count(), std::numeric_limits<double>::infinity());
  using E = std::pair<double, std::size_t>;
  std::priority_queue<E, std::vector<E>, std::greater<>> q;
  dist[grid.index(s)] = 0.0;
  q.emplace(0.0, grid.index(s));
  while (!q.empty()) {
    auto [d, i] = q.top();
    q.pop();
    if (d > dist[i]) continue;
    const Eigen::Vector3i c = grid.coords(i);
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          if (dx == 0 && dy == 0 && dz == 0) continue;
          const Eigen::Vector3i nb = c + Eigen::Vector3i(dx, dy, dz);
          if (!grid.contains(nb)) continue;
          bool ok = true;
          for (int z = std::min(c.z(), nb.z()); z <= std::max(c.z(), nb.z()); ++z)
            for (int y = std::min(c.y(), nb.y()); y <= std::max(c.y(), nb.y()); ++y)
              for (int x = std::min(c.x(), nb.x()); x <= std::max(c.x(), nb.x()); ++x)
                ok = ok && !grid.occupied(Eigen::Vector3i(x, y, z));
          if (!ok) continue;
          const double step = std::sqrt(static_cast<double>(dx * dx + dy * dy + dz * dz));
          const std::size_t j = grid.index(nb);
          if (d + step < dist[j]) {
            dist[j] = d + step;
            q.emplace(dist[j], j);
          }
        }
  }
  return dist[grid.index(g)] * grid.resolution();
}

}  // namespace

TEST_CASE("Segment-box distance is the minimum over the segment", "[REQ-WORLD-005]") {
  property("exact distance brackets the densely sampled minimum", [](std::uint64_t seed) {
    Rng rng(seed);
    const Box box = random_box(rng, 0.0, 5.0, 5.0);
    const Box space{{-5, -5, -5}, {15, 15, 15}};
    const V a = random_point(rng, space), b = random_point(rng, space);
    const double exact = std::sqrt(squared_distance(a, b, box));
    constexpr int kSamples = 2000;
    double sampled = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= kSamples; ++i) {
      sampled = std::min(sampled, std::sqrt(squared_distance(V(a + (b - a) * (double(i) / kSamples)), box)));
    }
    // The minimum is below every sample, and dist is 1-Lipschitz along the segment, so
    // it is at most half a sample spacing below the best sample.
    RC_ASSERT(exact <= sampled + kDistanceRounding);
    RC_ASSERT(exact >= sampled - 0.5 * (b - a).norm() / kSamples - kDistanceRounding);
  });
}

TEST_CASE("Point and segment queries agree with the distance definition", "[REQ-WORLD-004][REQ-WORLD-005]") {
  property("collision iff distance <= radius", [](std::uint64_t seed) {
    Rng rng(seed);
    const Map map = random_map(rng);
    const double r = rng.uniform(0.0, 1.0);
    const V p = random_point(rng, map.bounds()), q = random_point(rng, map.bounds());
    check_queries(map, all_obstacles(map), p, q, r);
  });
}

TEST_CASE("Voxel queries near the obstacles agree with the cubes' distances", "[REQ-WORLD-012]") {
  // Random points and short segments drawn next to blocked voxels, where the distance bound
  // cannot decide and the exact test must; plus rays against a brute-force slab test.
  property("voxel point, segment and ray queries are exact", [](std::uint64_t seed) {
    Rng rng(seed);
    VoxelSource source{random_layer(rng, rng.uniform01() < 0.5 ? 0.25 : 0.5), UnknownPolicy::kOccupied, "", ""};
    const Map map = Map::from_voxels(source);
    const std::vector<Box> obstacles = all_obstacles(map);
    RC_PRE(!obstacles.empty());
    for (int i = 0; i < 40; ++i) {
      const Box& near = obstacles[rng.uniform_index(obstacles.size())];
      const double r = rng.uniform(0.0, 1.0);
      const V p = random_point(rng, near.inflated(r + 0.5)), q = p + V(rng.normal(), rng.normal(), rng.normal());
      check_queries(map, obstacles, p, q, r);
      // First surface along a ray: the smallest entry distance over the cubes.
      const V dir = (q - p).normalized();
      double best = std::numeric_limits<double>::infinity();
      for (const Box& b : obstacles) {
        double t0 = 0.0, t1 = 20.0;
        for (int k = 0; k < 3; ++k) {
          if (dir[k] == 0.0) {
            if (p[k] < b.min[k] || p[k] > b.max[k]) t0 = 1e9;
            continue;
          }
          double ta = (b.min[k] - p[k]) / dir[k], tb = (b.max[k] - p[k]) / dir[k];
          if (ta > tb) std::swap(ta, tb);
          t0 = std::max(t0, ta);
          t1 = std::min(t1, tb);
        }
        if (t0 <= t1) best = std::min(best, t0);
      }
      const auto hit = map.raycast(p, dir, 20.0);
      RC_ASSERT(hit.has_value() == std::isfinite(best));
      if (hit) RC_ASSERT(std::fabs(*hit - best) <= 1e-9);
    }
  });
}

TEST_CASE("A ray's first surface among many boxes, some beyond the bounds, is the brute-force minimum", "[REQ-WORLD-016]") {
  // Map::raycast walks the bucket grid when a map has many boxes (a scan of a 1 km forest
  // casts millions of rays); its answer must be the smallest slab entry over every box,
  // bit for bit: boxes small and large (over many buckets), inside, straddling and wholly
  // beyond the bounds, rays from inside and outside the bounds, along and across the axes.
  property("bucket-walk raycast equals the minimum over all boxes", [](std::uint64_t seed) {
    Rng rng(seed);
    const Box bounds{{0, 0, 0}, {rng.uniform(5.0, 40.0), rng.uniform(5.0, 40.0), rng.uniform(2.0, 10.0)}};
    const Box around = bounds.inflated(3.0);
    std::vector<Box> boxes;
    const int n = 64 + static_cast<int>(rng.uniform_index(200));
    for (int i = 0; i < n; ++i) {
      const V a = random_point(rng, around);
      const double side = rng.uniform01() < 0.05 ? 20.0 : 1.0;
      boxes.push_back({a, a + V(rng.uniform(0.01, side), rng.uniform(0.01, side), rng.uniform(0.01, side))});
    }
    const Map map(bounds, 0.5, boxes);
    for (int r = 0; r < 200; ++r) {
      const V p = random_point(rng, rng.uniform01() < 0.8 ? bounds : around);
      V dir(rng.normal(), rng.normal(), rng.normal());
      if (rng.uniform01() < 0.2) dir[static_cast<int>(rng.uniform_index(3))] = 0.0;
      if (rng.uniform01() < 0.1) dir = V::Zero(), dir[static_cast<int>(rng.uniform_index(3))] = 1.0;
      if (dir.isZero()) continue;
      dir.normalize();
      const double range = rng.uniform(0.1, 60.0);
      std::optional<double> best;
      for (const Box& b : boxes) {
        double t0 = 0.0, t1 = range;
        bool miss = false;
        for (int k = 0; k < 3 && !miss; ++k) {
          if (dir[k] == 0.0) {
            miss = p[k] < b.min[k] || p[k] > b.max[k];
            continue;
          }
          double ta = (b.min[k] - p[k]) / dir[k], tb = (b.max[k] - p[k]) / dir[k];
          if (ta > tb) std::swap(ta, tb);
          t0 = std::max(t0, ta);
          t1 = std::min(t1, tb);
          miss = t0 > t1;
        }
        if (!miss && (!best || t0 < *best)) best = t0;
      }
      const std::optional<double> hit = map.raycast(p, dir, range);
      RC_ASSERT(hit.has_value() == best.has_value());
      if (hit) RC_ASSERT(*hit == *best);
    }
  });
}

TEST_CASE("The voxel grid covers every point within the robot radius of an obstacle", "[REQ-WORLD-006]") {
  property("point in collision => its cell is occupied", [](std::uint64_t seed) {
    Rng rng(seed);
    const Map map = random_map(rng);
    const double r = rng.uniform(0.0, 0.8);
    const VoxelGrid grid(map, r);
    for (int i = 0; i < 300; ++i) {
      const V p = random_point(rng, map.bounds());
      if (map.point_collision(p, r)) {
        const auto cell = grid.cell_of(p);
        RC_ASSERT(cell.has_value());
        RC_ASSERT(grid.occupied(*cell));
      }
    }
  });
}

TEST_CASE("A* finds the shortest 26-connected grid path", "[REQ-WORLD-007]") {
  property("A* cost equals Dijkstra's and is at least the straight line", [](std::uint64_t seed) {
    Rng rng(seed);
    const Map map = random_map(rng);
    const VoxelGrid grid(map, 0.0);
    const V s = random_point(rng, map.bounds()), g = random_point(rng, map.bounds());
    const auto sc = grid.cell_of(s), gc = grid.cell_of(g);
    RC_PRE(map.is_free(s) && map.is_free(g) && !grid.occupied(*sc) && !grid.occupied(*gc));
    const double reference = dijkstra_grid_cost(grid, *sc, *gc);
    if (std::isinf(reference)) {
      RC_ASSERT_THROWS_AS(astar(map, grid, s, g), miner::NoSolution);
      return;
    }
    const GridPath path = astar(map, grid, s, g);
    // Both sum the same steps in possibly different orders: a few ulps per step.
    RC_ASSERT(std::fabs(path.grid_cost - reference) <= 1e-9);
    RC_ASSERT(path.cost >= (g - s).norm() - kDistanceRounding);
    RC_ASSERT(path.cells.front() == *sc);
    RC_ASSERT(path.cells.back() == *gc);
  });
}

TEST_CASE("A* paths are collision-free in the continuous map for the robot radius", "[REQ-WORLD-008]") {
  property("every segment of an A* path is free", [](std::uint64_t seed) {
    Rng rng(seed);
    const Map map = random_map(rng);
    const double r = rng.uniform(0.0, 0.6);
    const VoxelGrid grid(map, r);
    const V s = random_point(rng, map.bounds()), g = random_point(rng, map.bounds());
    const auto sc = grid.cell_of(s), gc = grid.cell_of(g);
    RC_PRE(map.is_free(s, r) && map.is_free(g, r) && !grid.occupied(*sc) && !grid.occupied(*gc));
    try {
      const GridPath path = astar(map, grid, s, g);
      for (std::size_t i = 1; i < path.points.size(); ++i) {
        RC_ASSERT(map.segment_free(path.points[i - 1], path.points[i], r));
      }
    } catch (const miner::NoSolution&) {
      RC_SUCCEED("unreachable goal");
    }
  });
}

TEST_CASE("Maps survive a JSON round trip unchanged", "[REQ-WORLD-001]") {
  property("from_json(to_json(m)) == m", [](std::uint64_t seed) {
    Rng rng(seed);
    const Map map = random_box_map(rng);
    const Map back = Map::from_json(miner::parse_json(miner::dump_json(map.to_json()), "roundtrip"), "roundtrip");
    RC_ASSERT(back.to_json() == map.to_json());
    RC_ASSERT(back.obstacles().size() == map.obstacles().size());
    for (std::size_t i = 0; i < map.obstacles().size(); ++i) {
      RC_ASSERT(back.obstacles()[i].min == map.obstacles()[i].min);  // bit-exact doubles
      RC_ASSERT(back.obstacles()[i].max == map.obstacles()[i].max);
    }
  });
}

TEST_CASE("Every family map has a solvable query and the same bytes from the same seed", "[REQ-WORLD-011][REQ-WORLD-020]") {
  // Small sizes at a coarse resolution keep 100 maps cheap; the generator's logic is the
  // same at every size (the fixture-size maps are checked in map_generator_test).
  // Each case generates a map twice and runs A* on it; the `long` label runs 1000.
  const miner::testing::Cases cases{40, "two generated maps and an A* search per case"};
  property("family maps are solvable and deterministic", cases, [](std::uint64_t seed) {
    Rng rng(seed);
    const std::vector<std::string> families{"cluttered", "rooms", "forest", "multilevel", "mixed"};
    const GeneratorPreset p = generator_preset(families[rng.uniform_index(families.size())]);
    GeneratorOverrides o;
    o.size = small_family_size(rng, p);
    o.resolution = 0.25;
    try {
      const Map a = generate_map(p, seed, o);
      RC_ASSERT(miner::dump_json(a.to_json()) == miner::dump_json(generate_map(p, seed, o).to_json()));
      rc_assert_query_solvable(a);
    } catch (const miner::NoSolution&) {
      RC_FAIL("no solvable map in 16 attempts");
    }
  });
}

TEST_CASE("Every scan map has a free, solvable query in its own voxels and the same bytes from the same seed", "[REQ-WORLD-019]") {
  // A mapping run over a small map of a random family (a scan of a large one costs seconds of
  // ray casting); the `long` label runs 1000.
  const miner::testing::Cases cases{10, "two generated maps, two simulated mapping runs and A* per case"};
  property("scan maps are solvable in what the run saw, and deterministic", cases, [](std::uint64_t seed) {
    Rng rng(seed);
    const std::vector<std::string> families{"cluttered", "rooms", "forest", "multilevel"};
    const std::string base = families[rng.uniform_index(families.size())];
    GeneratorOverrides o;
    o.size = small_family_size(rng, generator_preset(base));
    o.resolution = 0.25;
    o.base = base;
    const GeneratorPreset p = generator_preset("scan");
    try {
      const Map a = generate_map(p, seed, o);
      const Map b = generate_map(p, seed, o);
      RC_ASSERT(a.voxels() != nullptr);
      RC_ASSERT(a.obstacles().empty());
      RC_ASSERT(octree_bt_bytes(a.voxels()->layer()) == octree_bt_bytes(b.voxels()->layer()));
      RC_ASSERT(a.voxels()->layer().count(VoxelState::kUnknown) > 0);
      RC_ASSERT(a.query()->robot_radius == p.robot_radius);
      rc_assert_query_solvable(a);
    } catch (const miner::NoSolution&) {
      RC_FAIL("no solvable scan in 16 attempts");
    }
  });
}
