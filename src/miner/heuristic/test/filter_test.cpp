#include <catch2/catch.hpp>

#include <algorithm>
#include <limits>

#include "miner/core/rng.hpp"
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

namespace {

/// The test's own statement of REQ-HEUR-016's chain: a breadth-first search over the cells
/// with R >= t, stepping to any of the 26 neighbours that is not solid and, with P, whose
/// axes of motion are passable in both cells.
bool chain_exists(const std::vector<float>& p, const std::vector<std::uint8_t>& env, const std::vector<std::uint8_t>& pass,
                  const Eigen::Vector3i& dims, const Eigen::Vector3i& s, const Eigen::Vector3i& g, float t) {
  const auto idx = [&](const Eigen::Vector3i& c) { return heuristic::cell_index(dims, c.x(), c.y(), c.z()); };
  const auto ok = [&](const Eigen::Vector3i& c) { return env[idx(c)] != heuristic::kSolid && p[idx(c)] >= t; };
  if (!ok(s) || !ok(g)) return false;
  std::vector<char> seen(p.size(), 0);
  std::vector<Eigen::Vector3i> queue{s};
  seen[idx(s)] = 1;
  for (std::size_t h = 0; h < queue.size(); ++h) {
    const Eigen::Vector3i u = queue[h];
    if (u == g) return true;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const Eigen::Vector3i d(dx, dy, dz), v = u + d;
          if (d == Eigen::Vector3i::Zero() || (v.array() < 0).any() || (v.array() >= dims.array()).any()) continue;
          if (seen[idx(v)] || !ok(v)) continue;
          bool passable = true;
          for (int a = 0; a < 3 && !pass.empty(); ++a)
            if (d[a] != 0) passable = passable && (pass[idx(u)] >> a & 1) && (pass[idx(v)] >> a & 1);
          if (!passable) continue;
          seen[idx(v)] = 1;
          queue.push_back(v);
        }
  }
  return false;
}

}  // namespace

TEST_CASE("The widest threshold is the largest one whose cells still join start and goal", "[REQ-HEUR-016]") {
  // Random grids with solid cells and, half the time, random P bits: the widest threshold must
  // be one of the grid's values at which a chain exists, and none above it may have one.
  miner::Rng rng(16);
  const Eigen::Vector3i dims(6, 5, 4);
  const auto n = static_cast<std::size_t>(dims.prod());
  int found = 0, none = 0;
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<float> p(n);
    std::vector<std::uint8_t> env(n), pass;
    for (std::size_t i = 0; i < n; ++i) {
      p[i] = static_cast<float>(rng.uniform01());
      env[i] = rng.uniform01() < 0.25 ? heuristic::kSolid : (rng.uniform01() < 0.5 ? heuristic::kPartial : heuristic::kFree);
    }
    if (trial % 2) {
      pass.resize(n);
      for (std::size_t i = 0; i < n; ++i) pass[i] = static_cast<std::uint8_t>(rng.uniform_index(8));
    }
    const Eigen::Vector3i s(0, static_cast<int>(rng.uniform_index(5)), 0), g(5, static_cast<int>(rng.uniform_index(5)), 3);
    const std::optional<float> w = heuristic::widest_threshold(p, env, dims, s, g, pass);
    INFO("trial " << trial);
    if (!w) {
      ++none;
      CHECK_FALSE(chain_exists(p, env, pass, dims, s, g, 0.0f));
      continue;
    }
    ++found;
    CHECK(std::find(p.begin(), p.end(), *w) != p.end());
    CHECK(chain_exists(p, env, pass, dims, s, g, *w));
    CHECK_FALSE(chain_exists(p, env, pass, dims, s, g, std::nextafter(*w, 2.0f)));
    // The rule: the fixed threshold when its cells hold a chain, the widest one below it otherwise.
    for (const double t0 : {0.05, 0.3, 0.9}) {
      const double t = heuristic::region_threshold(p, env, dims, s, g, t0, true, pass);
      CHECK(t == std::min(t0, std::max(static_cast<double>(*w), heuristic::kWidestFloor)));
      CHECK(heuristic::region_threshold(p, env, dims, s, g, t0, false, pass) == t0);
    }
  }
  // Both outcomes are exercised.
  CHECK(found >= 50);
  CHECK(none >= 10);
}

TEST_CASE("With the widest rule the raw region joins start and goal whenever non-solid cells do", "[REQ-HEUR-016]") {
  // A wall of solid cells at x = 4 with one partial cell, rated low by the network: the fixed
  // threshold leaves start and goal apart; the widest rule lowers it to that cell's value.
  Grid g;
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 4; ++k) g.set_p(i, j, k, i == 4 ? 0.0f : 0.8f);
  for (int j = 0; j < 4; ++j)
    for (int k = 0; k < 4; ++k) g.solid(4, j, k);
  g.env[heuristic::cell_index(kDims, 4, 2, 1)] = heuristic::kPartial;
  g.set_p(4, 2, 1, 0.03f);
  const double t = heuristic::region_threshold(g.p, g.env, kDims, {0, 1, 1}, {7, 1, 1}, 0.2, true);
  CHECK(t == Approx(0.03f));
  const auto f = heuristic::filter_region(g.p, g.env, kDims, {0, 1, 1}, {7, 1, 1}, t);
  CHECK(f.report.raw_connected);
  CHECK(f.report.threshold == t);
  CHECK(f.report.bridge_cells == 0);
  // P says the gap cell is blocked across x: no chain respects it, so the rule falls back to
  // the chain without P (a door narrower than a sub-cell).
  std::vector<std::uint8_t> pass(g.p.size(), heuristic::kPassAll);
  pass[heuristic::cell_index(kDims, 4, 2, 1)] = heuristic::kPassY | heuristic::kPassZ;
  CHECK_FALSE(heuristic::widest_threshold(g.p, g.env, kDims, {0, 1, 1}, {7, 1, 1}, pass));
  CHECK(heuristic::region_threshold(g.p, g.env, kDims, {0, 1, 1}, {7, 1, 1}, 0.2, true, pass) == Approx(0.03f));
  // A closed wall: no chain, the fixed threshold stays.
  g.env[heuristic::cell_index(kDims, 4, 2, 1)] = heuristic::kSolid;
  CHECK(heuristic::region_threshold(g.p, g.env, kDims, {0, 1, 1}, {7, 1, 1}, 0.2, true) == 0.2);
  // A gap rated 0 (the sigmoid's saturated tail) stops the threshold at the floor, never 0.
  g.env[heuristic::cell_index(kDims, 4, 2, 1)] = heuristic::kPartial;
  g.set_p(4, 2, 1, 0.0f);
  CHECK(heuristic::region_threshold(g.p, g.env, kDims, {0, 1, 1}, {7, 1, 1}, 0.2, true) == heuristic::kWidestFloor);
  CHECK_THROWS_WITH(heuristic::region_threshold(g.p, std::vector<std::uint8_t>(5), kDims, {0, 1, 1}, {7, 1, 1}, 0.2, true),
                    Catch::Matchers::Contains("grids of different sizes"));
  g.set_p(4, 2, 1, 0.03f);
  // A second gap the network rates higher wins, though it is farther.
  g.env[heuristic::cell_index(kDims, 4, 3, 3)] = heuristic::kPartial;
  g.set_p(4, 3, 3, 0.1f);
  CHECK(heuristic::region_threshold(g.p, g.env, kDims, {0, 1, 1}, {7, 1, 1}, 0.2, true) == Approx(0.1f));
}

TEST_CASE("Tenth campaign: the filter refuses cells outside its grid and a NaN threshold and a moved-from network is named",
          "[REQ-LIB-003][REQ-HEUR-007]") {
  using Catch::Matchers::Contains;
  Grid g;
  // L4: a start cell outside the grid corrupted the heap; a goal outside it was read past the end.
  CHECK_THROWS_WITH(heuristic::filter_region(g.p, g.env, kDims, Eigen::Vector3i(-5, 0, 0), Eigen::Vector3i(7, 3, 3), 0.5),
                    Contains("start cell (-5, 0, 0) lies outside the 8 x 4 x 4 grid"));
  CHECK_THROWS_WITH(heuristic::filter_region(g.p, g.env, kDims, Eigen::Vector3i(0, 0, 0), Eigen::Vector3i(8, 3, 3), 0.5),
                    Contains("goal cell (8, 3, 3)"));
  CHECK_THROWS_WITH(heuristic::widest_threshold(g.p, g.env, kDims, Eigen::Vector3i(0, 0, 0), Eigen::Vector3i(99, 0, 0), {}),
                    Contains("goal cell (99, 0, 0)"));
  CHECK_THROWS_WITH(heuristic::filter_region(g.p, g.env, kDims, Eigen::Vector3i(0, 0, 0), Eigen::Vector3i(7, 3, 3),
                                             std::numeric_limits<double>::quiet_NaN()),
                    Contains("threshold"));
  CHECK_THROWS_WITH(heuristic::filter_region(g.p, g.env, Eigen::Vector3i(0, 4, 4), Eigen::Vector3i(0, 0, 0),
                                             Eigen::Vector3i(0, 0, 0), 0.5),
                    Contains("at least 1"));
  CHECK_NOTHROW(heuristic::filter_region(g.p, g.env, kDims, Eigen::Vector3i(0, 0, 0), Eigen::Vector3i(7, 3, 3), 0.5));
  // L21: a network moved from answers with an error, the one moved to works.
  heuristic::Sgan a = heuristic::Sgan::builtin();
  const heuristic::Sgan b = std::move(a);
  CHECK_THROWS_WITH(a.architecture(), Contains("moved from"));  // NOLINT(bugprone-use-after-move)
  CHECK(b.architecture().dims == Eigen::Vector3i(32, 32, 32));
}

TEST_CASE("Tenth campaign: grid masks cells dilations and scale divisors are checked before use", "[REQ-LIB-003][REQ-HEUR-004]") {
  using Catch::Matchers::Contains;
  const Eigen::Vector3i d(4, 4, 4);
  CHECK_THROWS_WITH(heuristic::label_components(std::vector<std::uint8_t>(5, 1), Eigen::Vector3i(32, 32, 32)),
                    Contains("grid mask: 5 cells"));
  const std::vector<std::uint8_t> full(64, 1);
  CHECK(heuristic::connects(full, d, Eigen::Vector3i(0, 0, 0), Eigen::Vector3i(3, 3, 3)));
  CHECK_THROWS_WITH(heuristic::connects(full, d, Eigen::Vector3i(-1, 0, 0), Eigen::Vector3i(3, 3, 3)), Contains("grid cell a"));
  CHECK_THROWS_WITH(heuristic::connects(full, d, Eigen::Vector3i(0, 0, 0), Eigen::Vector3i(5, 5, 5)), Contains("grid cell b"));
  const miner::world::Box b{{0, 0, 0}, {4, 4, 4}};
  CHECK_THROWS_WITH(heuristic::encode_state(b, d, Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(3, 3, 3), -1), Contains("dilation"));
  CHECK_THROWS_WITH(heuristic::encode_state(b, d, Eigen::Vector3d(NAN, 1, 1), Eigen::Vector3d(3, 3, 3), 1),
                    Contains("state: start[0]"));
  CHECK(heuristic::encode_state(b, d, Eigen::Vector3d(0.5, 0.5, 0.5), Eigen::Vector3d(3.5, 3.5, 3.5), 0)[0] == 1);
  CHECK_THROWS_WITH(heuristic::scale_input(b, d, 0.2, 0.0), Contains("scale divisor"));
  CHECK_THROWS_WITH(heuristic::scale_input(b, d, 0.2, NAN), Contains("scale divisor"));
  // Recheck: dims of 0 encoded an empty environment; a NaN radius grew no obstacle (all free).
  const miner::world::Map walled(b, 0.5, {miner::world::Box{{1.5, 0, 0}, {2, 4, 4}}});
  CHECK_THROWS_WITH(heuristic::encode_environment(walled, Eigen::Vector3i(0, 4, 4), 0.2), Contains("region dims"));
  CHECK_THROWS_WITH(heuristic::encode_environment(walled, Eigen::Vector3i(1 << 20, 1 << 20, 1 << 20), 0.2),
                    Contains("more than the limit"));
  CHECK_THROWS_WITH(heuristic::encode_environment(walled, Eigen::Vector3i(4, 4, 4), std::nan("")),
                    Contains("encode: robot radius"));
  CHECK_THROWS_WITH(heuristic::encode_environment_passability(walled, Eigen::Vector3i(4, 4, 4), -1.0),
                    Contains("encode: robot radius"));
  CHECK_THROWS_WITH(heuristic::encode_state(b, Eigen::Vector3i(4, 0, 4), Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(3, 3, 3), 0),
                    Contains("region dims"));
  CHECK(heuristic::encode_environment(walled, Eigen::Vector3i(4, 4, 4), 0.2).size() == 64);
}

TEST_CASE("Fourteenth campaign: grid region filter and network calls refuse what lies outside them",
          "[REQ-LIB-003][REQ-HEUR-004][REQ-HEUR-005][REQ-HEUR-007]") {
  using Catch::Matchers::Contains;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Eigen::Vector3i d(8, 8, 8);
  // L1: component_of and solid_cells_in read past their inputs (a SEGV under ASan).
  const std::vector<std::uint8_t> full(512, 1);
  CHECK_THROWS_WITH(heuristic::component_of(full, d, 100000), Contains("cell index 100000 lies outside the mask's 512 cells"));
  CHECK_THROWS_WITH(heuristic::component_of(full, d, 512), Contains("cell index 512"));
  CHECK(heuristic::component_of(full, d, 511)[0] == 1);  // the last cell is in the grid
  CHECK_THROWS_WITH(heuristic::component_of(std::vector<std::uint8_t>(10, 1), d, 3), Contains("grid mask: 10 cells"));
  CHECK_THROWS_WITH(heuristic::solid_cells_in(full, std::vector<std::uint8_t>(10, heuristic::kSolid)),
                    Contains("mask has 512 cells and the environment 10"));
  CHECK(heuristic::solid_cells_in(full, std::vector<std::uint8_t>(512, heuristic::kSolid)) == 512);
  // L2: NaN was cast to int; indices past the grid answered coordinates and boxes outside it.
  const miner::world::Box b{{0, 0, 0}, {8, 8, 8}};
  CHECK_THROWS_WITH(heuristic::cell_of(b, d, Eigen::Vector3d(nan, 1, 1)), Contains("is not finite"));
  CHECK(heuristic::cell_of(b, d, Eigen::Vector3d(-1e300, 1.5, 99)) == Eigen::Vector3i(0, 1, 7));  // clamped
  CHECK_THROWS_WITH(heuristic::cell_coords(d, 512), Contains("grid cell index 512 lies outside the 8 x 8 x 8 grid"));
  CHECK(heuristic::cell_coords(d, 511) == Eigen::Vector3i(7, 7, 7));
  const auto region = miner::plan::HeuristicRegion::from_path(b, d, {Eigen::Vector3d(0.5, 0.5, 0.5), Eigen::Vector3d(7.5, 0.5, 0.5)}, 0, "t");
  CHECK_THROWS_WITH(region.coords(100000), Contains("region cell index 100000 lies outside the region's 512 cells"));
  CHECK_THROWS_WITH(region.cell_box(512), Contains("index 512"));
  CHECK(region.cell_box(511).max == Eigen::Vector3d(8, 8, 8));
  // L5: E level 9, NaN probabilities and a NaN threshold of the widest rule were taken.
  Grid g;
  const Eigen::Vector3i s(0, 0, 0), e(7, 3, 3);
  g.env[5] = 9;
  CHECK_THROWS_WITH(heuristic::filter_region(g.p, g.env, kDims, s, e, 0.5), Contains("E cell 5 holds 9"));
  g.env[5] = heuristic::kFree;
  g.p[7] = static_cast<float>(nan);
  CHECK_THROWS_WITH(heuristic::widest_threshold(g.p, g.env, kDims, s, e), Contains("R cell 7 is nan"));
  g.p[7] = 1.5f;
  CHECK_THROWS_WITH(heuristic::filter_region(g.p, g.env, kDims, s, e, 0.5), Contains("R cell 7 is 1.5"));
  g.p[7] = 1.0f;
  CHECK_THROWS_WITH(heuristic::widest_threshold(g.p, g.env, kDims, s, e, std::vector<std::uint8_t>(128, 8)),
                    Contains("P cell 0 holds 8"));
  for (const bool widest : {false, true})
    CHECK_THROWS_WITH(heuristic::region_threshold(g.p, g.env, kDims, s, e, nan, widest), Contains("threshold must be a number"));
  CHECK(heuristic::region_threshold(g.p, g.env, kDims, s, e, 0.5, false) == 0.5);
  // L3: forward() returned NaN probabilities for a NaN or an overflowing input; predict() took
  // E, S and P values outside their levels.
  const heuristic::Sgan net = heuristic::Sgan::builtin();
  const std::size_t n = static_cast<std::size_t>(net.architecture().dims.prod());
  const std::size_t pc = static_cast<std::size_t>(net.architecture().passability_channels);
  std::vector<float> env(n, 0.0f), state(n, 0.0f), noise(n, 0.0f), blocked(pc * n, 0.0f);
  state[0] = state[n - 1] = 1.0f;
  const std::vector<float> scale = net.architecture().scale_channels ? std::vector<float>{0.5f, 0.5f, 0.5f}
                                                                     : std::vector<float>{};
  const auto probabilities = net.forward(env, state, noise, scale, blocked);
  CHECK(std::all_of(probabilities.begin(), probabilities.end(), [](float v) { return v >= 0.0f && v <= 1.0f; }));
  env[17] = static_cast<float>(nan);
  CHECK_THROWS_WITH(net.forward(env, state, noise, scale, blocked), Contains("input env[17] is nan"));
  env[17] = 0.0f;
  noise[3] = std::numeric_limits<float>::infinity();
  CHECK_THROWS_WITH(net.forward(env, state, noise, scale, blocked), Contains("input noise[3] is inf"));
  std::fill(noise.begin(), noise.end(), 3e38f);
  CHECK_THROWS_WITH(net.forward(env, state, noise, scale, blocked), Contains("not a probability: a layer overflowed"));
  std::vector<std::uint8_t> E(n, heuristic::kFree), S(n, 0), P(n, heuristic::kPassAll);
  S[0] = S[n - 1] = 1;
  miner::Rng rng(1);
  const miner::world::Box bounds{{0, 0, 0}, {10, 10, 4}};
  CHECK(net.predict(E, S, P, bounds, 0.2, rng).size() == n);
  E[9] = 9;
  CHECK_THROWS_WITH(net.predict(E, S, P, bounds, 0.2, rng), Contains("E cell 9 holds 9, outside its levels 0..2"));
  E[9] = heuristic::kSolid;
  S[4] = 2;
  CHECK_THROWS_WITH(net.predict(E, S, P, bounds, 0.2, rng), Contains("S cell 4 holds 2"));
  S[4] = 0;
  if (pc != 0) {
    P[6] = 255;
    CHECK_THROWS_WITH(net.predict(E, S, P, bounds, 0.2, rng), Contains("P cell 6 holds 255"));
  }
}

TEST_CASE("The level and probability checks name the first offending cell anywhere in a grid of many check blocks",
          "[REQ-LIB-003][REQ-HEUR-002][REQ-HEUR-007]") {
  using Catch::Matchers::Equals;
  // Session 35 made the checks branch-free per block of cells (the query checks its grids
  // several times); an offender in any block, at either end of one, or in a short last block is
  // still found, and the first of two is the one named.
  constexpr std::size_t kCells = 3 * 4096 + 17;
  for (const std::size_t at : {std::size_t{0}, std::size_t{4095}, std::size_t{4096}, std::size_t{8191}, kCells - 1}) {
    std::vector<std::uint8_t> levels(kCells, heuristic::kSolid);
    CHECK_NOTHROW(heuristic::require_levels(levels, heuristic::kSolid, "E"));
    levels[at] = 3;
    if (at + 5 < kCells) levels[at + 5] = 7;
    CHECK_THROWS_WITH(heuristic::require_levels(levels, heuristic::kSolid, "E"),
                      Equals("E cell " + std::to_string(at) + " holds 3, outside its levels 0..2"));
    std::vector<float> p(kCells, 1.0f);
    p[1] = 0.0f;
    CHECK(heuristic::first_non_probability(p) == kCells);
    for (const float bad : {std::numeric_limits<float>::quiet_NaN(), -1e-9f, 1.0000001f,
                            std::numeric_limits<float>::infinity()}) {
      p[at] = bad;
      if (at + 3 < kCells) p[at + 3] = -5.0f;
      CHECK(heuristic::first_non_probability(p) == at);
      p[at] = 0.5f;
    }
  }
  CHECK(heuristic::first_non_probability({}) == 0);
}
