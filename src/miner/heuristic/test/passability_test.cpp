#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "miner/core/rng.hpp"
#include "miner/heuristic/grid.hpp"
#include "miner/world/map.hpp"

using namespace miner;
using heuristic::kPassAll;
using heuristic::kPassX;
using heuristic::kPassY;
using heuristic::kPassZ;

namespace {

constexpr int kN = heuristic::kPassabilitySubcells;

/// The P bits of a sub-cell mask by a plain breadth-first search over the free sub-cells,
/// face neighbours only: the definition that passability_of's bit-parallel flood must meet.
std::uint8_t passability_by_search(std::uint64_t free) {
  const auto bit = [](int x, int y, int z) { return x + kN * (y + kN * z); };
  std::uint8_t out = 0;
  for (int a = 0; a < 3; ++a) {
    std::vector<int> queue;
    std::vector<bool> seen(64, false);
    for (int i = 0; i < 64; ++i) {
      const int c[3] = {i % kN, (i / kN) % kN, i / (kN * kN)};
      if (c[a] == 0 && ((free >> i) & 1U)) {
        seen[static_cast<std::size_t>(i)] = true;
        queue.push_back(i);
      }
    }
    bool reached = false;
    for (std::size_t head = 0; head < queue.size(); ++head) {
      const int i = queue[head];
      int c[3] = {i % kN, (i / kN) % kN, i / (kN * kN)};
      if (c[a] == kN - 1) reached = true;
      for (int b = 0; b < 3; ++b)
        for (int d : {-1, 1}) {
          int n[3] = {c[0], c[1], c[2]};
          n[b] += d;
          if (n[b] < 0 || n[b] >= kN) continue;
          const int j = bit(n[0], n[1], n[2]);
          if (!((free >> j) & 1U) || seen[static_cast<std::size_t>(j)]) continue;
          seen[static_cast<std::size_t>(j)] = true;
          queue.push_back(j);
        }
    }
    if (reached) out = static_cast<std::uint8_t>(out | (1U << a));
  }
  return out;
}

heuristic::Encoding encode(const world::Map& map, const Eigen::Vector3i& dims, double radius) {
  return heuristic::encode_environment_passability(map, dims, radius);
}

}  // namespace

TEST_CASE("P's flood agrees with a breadth-first search on random sub-cell masks", "[REQ-HEUR-015]") {
  CHECK(heuristic::passability_of(~std::uint64_t{0}) == kPassAll);
  CHECK(heuristic::passability_of(0) == 0);
  Rng rng(15, 0);
  int disagreements = 0, passable_x = 0, blocked_x = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    // Densities from mostly free to mostly blocked, so every bit is seen both ways.
    const double p_free = 0.35 + 0.5 * rng.uniform01();
    std::uint64_t free = 0;
    for (int i = 0; i < 64; ++i)
      if (rng.uniform01() < p_free) free |= std::uint64_t{1} << i;
    const std::uint8_t want = passability_by_search(free);
    disagreements += heuristic::passability_of(free) != want;
    ((want & kPassX) ? passable_x : blocked_x) += 1;
  }
  CHECK(disagreements == 0);
  CHECK(passable_x > 1000);
  CHECK(blocked_x > 1000);
  // A plane of blocked sub-cells across x stops x only; one hole in it lets x through.
  std::uint64_t wall = ~std::uint64_t{0};
  for (int z = 0; z < kN; ++z)
    for (int y = 0; y < kN; ++y) wall &= ~(std::uint64_t{1} << (2 + kN * (y + kN * z)));
  CHECK(heuristic::passability_of(wall) == (kPassY | kPassZ));
  CHECK(heuristic::passability_of(wall | (std::uint64_t{1} << (2 + kN * (1 + kN * 3)))) == kPassAll);
}

TEST_CASE("P tells a wall's door from the wall on a box map, where E cannot", "[REQ-HEUR-015]") {
  // A 0.2 m wall across x at x = 5.5 m (inside the cells x in [5, 6]) with a 1.2 m door at
  // y in [4.4, 5.6], z below 2.1 m; robot radius 0.2, 1 m cells of 4 sub-cells (0.25 m).
  using world::Box;
  const world::Map map(Box{{0, 0, 0}, {10, 10, 4}}, 0.1,
                       {Box{{5.4, 0, 0}, {5.6, 4.4, 4}}, Box{{5.4, 5.6, 0}, {5.6, 10, 4}},
                        Box{{5.4, 4.4, 2.1}, {5.6, 5.6, 4}}});
  const Eigen::Vector3i dims(10, 10, 4);
  const heuristic::Encoding enc = encode(map, dims, 0.2);
  const auto at = [&](const std::vector<std::uint8_t>& g, int i, int j, int k) {
    return g[heuristic::cell_index(dims, i, j, k)];
  };
  // The same E as encode_environment: P is beside E, not instead of it.
  CHECK(enc.environment == heuristic::encode_environment(map, dims, 0.2));
  // Wall cells and the door cell are both partial in E...
  CHECK(at(enc.environment, 5, 2, 0) == heuristic::kPartial);
  CHECK(at(enc.environment, 5, 4, 0) == heuristic::kPartial);
  // ... and P says which lets the robot across x.
  CHECK(at(enc.passability, 5, 2, 0) == (kPassY | kPassZ));
  CHECK(at(enc.passability, 5, 2, 3) == (kPassY | kPassZ));
  CHECK(at(enc.passability, 5, 4, 0) == kPassAll);  // the door (y in [4.4, 5.6] grown to [4.6, 5.4])
  CHECK(at(enc.passability, 5, 5, 1) == kPassAll);
  CHECK(at(enc.passability, 5, 4, 3) == (kPassY | kPassZ));  // above the lintel
  // Free cells pass every way; the cells beside the wall are free.
  CHECK(at(enc.environment, 2, 2, 0) == heuristic::kFree);
  CHECK(at(enc.passability, 2, 2, 0) == kPassAll);
}

TEST_CASE("P of solid cells is 0 and of a voxel wall with a gap is read from its voxels", "[REQ-HEUR-015]") {
  // 40 x 40 x 16 voxels of 0.25 m: a wall one voxel thick at x voxel 21 (x in [5.25, 5.5] m),
  // with a gap of 6 voxels (y in [4.5, 6] m) at z below 2 m; a solid block of 4 m at the corner.
  const Eigen::Vector3i vd(40, 40, 16);
  std::vector<std::uint8_t> s(static_cast<std::size_t>(vd.prod()), 0);
  for (int z = 0; z < vd.z(); ++z)
    for (int y = 0; y < vd.y(); ++y) {
      const bool gap = y >= 18 && y < 24 && z < 8;
      if (!gap) s[(static_cast<std::size_t>(z) * vd.y() + y) * vd.x() + 21] = static_cast<std::uint8_t>(world::VoxelState::kOccupied);
      for (int x = 0; x < 16; ++x)
        if (y < 16) s[(static_cast<std::size_t>(z) * vd.y() + y) * vd.x() + x] = static_cast<std::uint8_t>(world::VoxelState::kOccupied);
    }
  auto layer = std::make_shared<const world::VoxelLayer>(Eigen::Vector3i::Zero(), 0.25, vd, std::move(s));
  const world::Map map = world::Map::from_voxels({layer, world::UnknownPolicy::kOccupied, "", ""});
  const Eigen::Vector3i dims(10, 10, 4);  // 1 m cells, 4^3 voxels each
  const heuristic::Encoding enc = encode(map, dims, 0.0);
  const auto at = [&](const std::vector<std::uint8_t>& g, int i, int j, int k) {
    return g[heuristic::cell_index(dims, i, j, k)];
  };
  CHECK(enc.environment == heuristic::encode_environment(map, dims, 0.0));
  CHECK(at(enc.environment, 1, 1, 1) == heuristic::kSolid);
  CHECK(at(enc.passability, 1, 1, 1) == 0);
  CHECK(at(enc.environment, 5, 7, 0) == heuristic::kPartial);
  CHECK(at(enc.passability, 5, 7, 0) == (kPassY | kPassZ));  // the wall
  CHECK(at(enc.environment, 5, 4, 0) == heuristic::kPartial);  // y voxels 16..19: wall, wall, gap, gap
  CHECK(at(enc.passability, 5, 4, 0) == kPassAll);
  CHECK(at(enc.passability, 5, 5, 3) == (kPassY | kPassZ));  // above it
  CHECK(at(enc.passability, 8, 8, 0) == kPassAll);
}

namespace {

/// The sub-cells of `cell` whose centres lie in the closed box g, by testing each centre.
std::uint64_t centres_in_box(const world::Box& cell, const world::Box& g) {
  std::uint64_t mask = 0;
  const Eigen::Vector3d h = cell.extent() / kN;
  for (int z = 0; z < kN; ++z)
    for (int y = 0; y < kN; ++y)
      for (int x = 0; x < kN; ++x) {
        const Eigen::Vector3d c = cell.min + Eigen::Vector3d(x + 0.5, y + 0.5, z + 0.5).cwiseProduct(h);
        if ((c.array() >= g.min.array()).all() && (c.array() <= g.max.array()).all())
          mask |= std::uint64_t{1} << (x + kN * (y + kN * z));
      }
  return mask;
}

}  // namespace

TEST_CASE("A grown box blocks exactly the sub-cells whose centres lie in it: the closed box", "[REQ-HEUR-015]") {
  // subcells_inside against a direct test of every 4^3 centre. (1) Dyadic cells and boxes
  // whose faces fall on centres (a centre on a face is inside: closed box), half-way between
  // centres, on cell faces and past the cell, exactly representable so both sides are exact.
  Rng rng(26, 0);
  const world::Box unit{{0, 0, 0}, {1, 1, 1}};
  int on_face = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    const Eigen::Vector3d scale(std::ldexp(1.0, static_cast<int>(rng.uniform_index(4)) - 1),
                                std::ldexp(1.0, static_cast<int>(rng.uniform_index(4)) - 1),
                                std::ldexp(1.0, static_cast<int>(rng.uniform_index(4)) - 1));
    const Eigen::Vector3d origin(static_cast<double>(rng.uniform_index(9)) - 4.0,
                                 static_cast<double>(rng.uniform_index(9)) - 4.0,
                                 static_cast<double>(rng.uniform_index(9)) - 4.0);
    const world::Box cell{origin, origin + scale};
    world::Box g;
    for (int a = 0; a < 3; ++a) {
      // Eighths of the cell from -2/8 to 10/8: centres are the odd eighths 1, 3, 5, 7.
      int lo = static_cast<int>(rng.uniform_index(13)) - 2, hi = static_cast<int>(rng.uniform_index(13)) - 2;
      if (lo > hi) std::swap(lo, hi);
      g.min[a] = origin[a] + scale[a] * lo / 8.0;
      g.max[a] = origin[a] + scale[a] * hi / 8.0;
      on_face += (hi % 2 != 0) && hi >= 1 && hi <= 7;
    }
    const std::uint64_t want = centres_in_box(cell, g);
    INFO("trial " << trial << ": cell " << cell.min.transpose() << " .. " << cell.max.transpose() << ", box "
                  << g.min.transpose() << " .. " << g.max.transpose());
    REQUIRE(heuristic::subcells_inside(cell, g) == want);
  }
  CHECK(on_face > 1000);  // many boxes end exactly on a centre
  CHECK(heuristic::subcells_inside(unit, unit) == ~std::uint64_t{0});
  CHECK(heuristic::subcells_inside(unit, world::Box{{0.375, 0.375, 0.375}, {0.625, 0.625, 0.625}}) ==
        centres_in_box(unit, world::Box{{0.375, 0.375, 0.375}, {0.625, 0.625, 0.625}}));
  CHECK(heuristic::subcells_inside(unit, world::Box{{0, 0, 0}, {0.124, 1, 1}}) == 0);  // short of the first centre
  // (2) Random cells and boxes of any size (no face on a centre but by chance, skipped).
  for (int trial = 0; trial < 4000; ++trial) {
    const Eigen::Vector3d lo(rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-5, 5));
    const Eigen::Vector3d ext(rng.uniform(0.1, 3), rng.uniform(0.1, 3), rng.uniform(0.1, 3));
    const world::Box cell{lo, lo + ext};
    world::Box g;
    bool near_centre = false;
    for (int a = 0; a < 3; ++a) {
      double u = rng.uniform(-0.3, 1.3), v = rng.uniform(-0.3, 1.3);
      if (u > v) std::swap(u, v);
      g.min[a] = lo[a] + u * ext[a];
      g.max[a] = lo[a] + v * ext[a];
      for (int s = 0; s < kN; ++s)
        for (double f : {u, v}) near_centre = near_centre || std::abs(f - (s + 0.5) / kN) < 1e-9;
    }
    if (near_centre) continue;
    INFO("random trial " << trial);
    REQUIRE(heuristic::subcells_inside(cell, g) == centres_in_box(cell, g));
  }
}

TEST_CASE("P of a partial cell is the flood of the sub-cells whose centres lie outside every grown box", "[REQ-HEUR-015]") {
  // Through the public encoding: one box on a 4 x 4 x 4 map of 1 m cells, grown by 0.125 m, its
  // faces on eighths of a cell (so the grown faces fall on sub-cell centres or half-way): each
  // partial cell's P is passability_of of the centres outside the grown box.
  Rng rng(2619, 0);
  const Eigen::Vector3i dims(4, 4, 4);
  const double radius = 0.125;
  int partial = 0;
  for (int trial = 0; trial < 300; ++trial) {
    world::Box box;
    for (int a = 0; a < 3; ++a) {
      int lo = static_cast<int>(rng.uniform_index(31)) + 1, hi = static_cast<int>(rng.uniform_index(31)) + 1;
      if (lo > hi) std::swap(lo, hi);
      if (lo == hi) ++hi;
      box.min[a] = lo / 8.0;
      box.max[a] = hi / 8.0;
    }
    const world::Map map(world::Box{{0, 0, 0}, {4, 4, 4}}, 0.125, {box});
    const heuristic::Encoding enc = encode(map, dims, radius);
    const world::Box grown = box.inflated(radius);
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) {
          const std::size_t idx = heuristic::cell_index(dims, i, j, k);
          if (enc.environment[idx] != heuristic::kPartial) continue;
          ++partial;
          const world::Box cell{Eigen::Vector3d(i, j, k), Eigen::Vector3d(i + 1, j + 1, k + 1)};
          INFO("trial " << trial << ", cell " << i << " " << j << " " << k);
          REQUIRE(enc.passability[idx] == heuristic::passability_of(~centres_in_box(cell, grown)));
        }
  }
  CHECK(partial > 1000);
}
