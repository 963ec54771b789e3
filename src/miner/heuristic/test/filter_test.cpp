#include <catch2/catch.hpp>

#include <algorithm>

#include "miner/heuristic/grid.hpp"
#include "miner/heuristic/region_filter.hpp"
#include "miner/heuristic/sgan.hpp"
#include "miner/world/map.hpp"
#include "miner/world/map_generator.hpp"

namespace heuristic = miner::heuristic;

namespace {

const Eigen::Vector3i kDims(8, 4, 4);

struct Grid {
  std::vector<float> p = std::vector<float>(128, 0.0f);
  std::vector<std::uint8_t> env = std::vector<std::uint8_t>(128, heuristic::kFree);
  void set_p(int i, int j, int k, float v) { p[heuristic::cell_index(kDims, i, j, k)] = v; }
  void solid(int i, int j, int k) { env[heuristic::cell_index(kDims, i, j, k)] = heuristic::kSolid; }
  bool in(const heuristic::FilteredRegion& f, int i, int j, int k) const {
    return f.mask[heuristic::cell_index(kDims, i, j, k)] != 0;
  }
};

}  // namespace

TEST_CASE("The filter keeps a connected safe raw region as it is", "[REQ-HEUR-007]") {
  Grid g;
  for (int i = 0; i < 8; ++i) g.set_p(i, 1, 1, 0.9f);
  const auto f = heuristic::filter_region(g.p, g.env, kDims, {0, 1, 1}, {7, 1, 1}, 0.5);
  CHECK(f.report.raw_connected);
  CHECK(f.report.raw_safe);
  CHECK(f.report.cells == 8);
  CHECK(f.report.bridge_cells == 0);
  CHECK(f.report.connected);
  CHECK(heuristic::connects(f.mask, kDims, {0, 1, 1}, {7, 1, 1}));
  CHECK(f.report.safe);
}

TEST_CASE("The filter drops solid cells and islands, and bridges start to goal through non-solid cells",
          "[REQ-HEUR-007]") {
  Grid g;
  for (int i = 0; i < 8; ++i) g.set_p(i, 1, 1, 0.9f);
  g.solid(4, 1, 1);            // the raw region crosses an obstacle: unsafe
  g.set_p(2, 3, 3, 0.8f);      // an island far from the line
  g.set_p(5, 0, 1, 0.3f);      // below threshold but the best way round
  const auto f = heuristic::filter_region(g.p, g.env, kDims, {0, 1, 1}, {7, 1, 1}, 0.5);
  CHECK(f.report.raw_connected);
  CHECK_FALSE(f.report.raw_safe);
  CHECK(f.report.solid_dropped == 1);
  CHECK(f.report.island_dropped == 1);
  CHECK_FALSE(g.in(f, 2, 3, 3));
  CHECK_FALSE(g.in(f, 4, 1, 1));
  CHECK(f.report.bridge_cells > 0);
  CHECK(f.report.connected);
  CHECK(f.report.safe);
  CHECK(heuristic::connects(f.mask, kDims, {0, 1, 1}, {7, 1, 1}));
  CHECK(heuristic::solid_cells_in(f.mask, g.env) == 0);
}

TEST_CASE("An empty raw region is bridged, a walled-off goal stays unconnected and nothing unsafe is added",
          "[REQ-HEUR-007]") {
  Grid g;
  const auto f = heuristic::filter_region(g.p, g.env, kDims, {0, 0, 0}, {7, 3, 3}, 0.5);
  CHECK(f.report.raw_cells == 0);
  CHECK_FALSE(f.report.raw_connected);
  CHECK(f.report.connected);
  CHECK(heuristic::connects(f.mask, kDims, {0, 0, 0}, {7, 3, 3}));
  Grid wall;
  for (int j = 0; j < 4; ++j)
    for (int k = 0; k < 4; ++k) wall.solid(4, j, k);
  const auto w = heuristic::filter_region(wall.p, wall.env, kDims, {0, 0, 0}, {7, 3, 3}, 0.5);
  CHECK_FALSE(w.report.connected);
  CHECK_FALSE(heuristic::connects(w.mask, kDims, {0, 0, 0}, {7, 3, 3}));
  CHECK(w.report.safe);
  CHECK(w.report.bridge_cells == 0);
  CHECK(w.report.cells == 2);  // start and goal cells only
}

TEST_CASE("On generated maps the filtered sGAN region is connected and safe for every A*-solvable query",
          "[REQ-HEUR-007]") {
  const heuristic::Sgan sgan = heuristic::Sgan::builtin();
  for (std::uint64_t seed : {11u, 12u, 13u}) {
    const miner::world::GeneratorPreset preset = miner::world::generator_preset("sim");
    const miner::world::Map map = miner::world::generate_map(preset, seed);
    const auto& q = *map.query();
    const heuristic::HeuristicQuery h =
        heuristic::query_region(sgan, map, q.start, q.goal, preset.robot_radius, seed);
    INFO("map seed " << seed);
    CHECK(h.report.connected);
    CHECK(h.report.safe);
    CHECK(h.region.contains(q.start));
    CHECK(h.region.contains(q.goal));
    CHECK(h.region.source() == "sgan-filtered");
    // The raw variant carries the network's probabilities and its threshold.
    const heuristic::HeuristicQuery raw =
        heuristic::query_region(sgan, map, q.start, q.goal, preset.robot_radius, seed, false);
    CHECK(raw.region.source() == "sgan-raw");
    CHECK(raw.probabilities == h.probabilities);
  }
}

TEST_CASE("The bridge takes the chain the generator rates higher when lengths tie", "[REQ-HEUR-007]") {
  Grid g;
  // A solid wall at x = 4 with two holes, both adjacent to start (3,1,1) and goal (5,1,1).
  for (int j = 0; j < 4; ++j)
    for (int k = 0; k < 4; ++k)
      if (!(j == 0 && k == 0) && !(j == 2 && k == 2)) g.solid(4, j, k);
  g.set_p(4, 2, 2, 0.4f);  // below the threshold, but rated higher than the other hole (p = 0)
  const auto f = heuristic::filter_region(g.p, g.env, kDims, {3, 1, 1}, {5, 1, 1}, 0.5);
  REQUIRE(f.report.connected);
  CHECK(g.in(f, 4, 2, 2));         // the cheaper chain: cost 1 + (1 - 0.4)
  CHECK_FALSE(g.in(f, 4, 0, 0));   // not the hole of cost 2 (lower index: the tie-break pick)
  CHECK(f.report.safe);
}
