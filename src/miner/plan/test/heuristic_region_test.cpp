#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

#include <fstream>

#include "miner/core/error.hpp"
#include "miner/core/rng.hpp"
#include "miner/plan/heuristic_region.hpp"
#include "miner/plan/reference.hpp"
#include "miner/plan/rrt_star.hpp"
#include "plan_test_maps.hpp"

using miner::plan::HeuristicRegion;
using miner::world::Box;
using Catch::Matchers::Contains;
using V = Eigen::Vector3d;
using I = Eigen::Vector3i;

namespace {
HeuristicRegion two_cells() {
  // 4 x 2 x 1 cells over [0,8] x [0,2] x [0,1]; cells 1 and 6 in H.
  std::vector<double> p(8, 0.1);
  p[1] = 0.9;
  p[6] = 0.5;
  return HeuristicRegion(Box{{0, 0, 0}, {8, 2, 1}}, I(4, 2, 1), p, 0.5, "test");
}
}  // namespace

TEST_CASE("A region's H is the cells at or above the threshold and its samples stay inside them", "[REQ-PLAN-004][REQ-PLAN-005]") {
  const HeuristicRegion r = two_cells();
  REQUIRE(r.cells() == std::vector<std::size_t>{1, 6});
  CHECK(r.volume() == Approx(2 * 2.0));
  CHECK(r.contains(V(2.5, 0.5, 0.5)));   // cell (1, 0, 0)
  CHECK(r.contains(V(4.5, 1.5, 0.5)));   // cell (2, 1, 0) = index 6
  CHECK_FALSE(r.contains(V(0.5, 0.5, 0.5)));
  CHECK_FALSE(r.contains(V(9, 0.5, 0.5)));  // outside the bounds
  miner::Rng rng(5);
  int in_first = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const V x = r.sample(rng);
    REQUIRE(r.contains(x));
    in_first += x.x() < 4.0;
  }
  // Both cells have the same volume: each gets half the samples (6 sigma of 0.0035).
  CHECK(std::abs(in_first / static_cast<double>(n) - 0.5) < 6 * 0.5 / std::sqrt(n));
}

TEST_CASE("A region round-trips through miner-region-v1 and bad files name the field", "[REQ-PLAN-005]") {
  const HeuristicRegion r = two_cells();
  const std::string path = miner::plan::test::temp_path("two.json");
  r.save(path);
  const HeuristicRegion back = HeuristicRegion::load(path);
  CHECK(back.cells() == r.cells());
  CHECK(back.probabilities() == r.probabilities());
  CHECK(back.source() == "test");
  // Fifteenth campaign F10: a threshold load() refuses (subnormal) is refused by save().
  const HeuristicRegion tiny(Box{{0, 0, 0}, {8, 4, 4}}, I(2, 1, 1), {1.0, 0.5}, 1e-310);
  CHECK_THROWS_WITH(tiny.save(path), Contains(path + ": cannot be written: the number at /threshold"));
  CHECK(HeuristicRegion::load(path).cells() == r.cells());  // the earlier file is kept

  miner::Json doc = r.to_json();
  doc["format"] = "other";
  CHECK_THROWS_WITH(HeuristicRegion::from_json(doc, "r.json"), Contains("unknown format tag"));
  doc = r.to_json();
  doc["probabilities"][3] = 1.5;
  CHECK_THROWS_WITH(HeuristicRegion::from_json(doc, "r.json"), Contains("probabilities[3]") && Contains("[0, 1]"));
  // Both ends of [0, 1] (held-out audit 8, h8-plan-01: a negative probability was accepted).
  for (const double bad : {-0.5, -1e-12, 1.0 + 1e-12}) {
    doc = r.to_json();
    doc["probabilities"][3] = bad;
    CHECK_THROWS_WITH(HeuristicRegion::from_json(doc, "r.json"), Contains("probabilities[3]") && Contains("[0, 1]"));
  }
  for (const double good : {0.0, 1.0}) {
    doc = r.to_json();
    doc["probabilities"][3] = good;
    CHECK_NOTHROW(HeuristicRegion::from_json(doc, "r.json"));
  }
  doc = r.to_json();
  doc["probabilities"].erase(0);
  CHECK_THROWS_WITH(HeuristicRegion::from_json(doc, "r.json"), Contains("expected nx*ny*nz = 8 values, got 7"));
  doc = r.to_json();
  doc["dims"] = {4, 0, 2};
  CHECK_THROWS_WITH(HeuristicRegion::from_json(doc, "r.json"), Contains("dims"));
  doc = r.to_json();
  doc.erase("threshold");  // H depends on it: never defaulted
  CHECK_THROWS_WITH(HeuristicRegion::from_json(doc, "r.json"), Contains("r.json: threshold: missing required field"));
  doc = r.to_json();
  doc["threshold"] = 0.0;
  CHECK_THROWS_WITH(HeuristicRegion::from_json(doc, "r.json"), Contains("threshold"));
  doc = r.to_json();
  doc["probabilities"][2] = "x";
  CHECK_THROWS_WITH(HeuristicRegion::from_json(doc, "r.json"), Contains("probabilities[2]"));
  // The source is provenance printed in reports: one printable line (issue 20, S7).
  for (const std::string& bad : {std::string("a\nb"), std::string("tab\there"), std::string(513, 'x')}) {
    doc = r.to_json();
    doc["source"] = bad;
    CHECK_THROWS_WITH(HeuristicRegion::from_json(doc, "r.json"), Contains("r.json: source: must be one line of at most 512 bytes"));
  }
  doc = r.to_json();
  doc["source"] = std::string(512, 'x');
  CHECK_NOTHROW(HeuristicRegion::from_json(doc, "r.json"));
  // The constructor keeps the same rule, so what saves also loads (sixteenth campaign F7: a
  // region made in code with a newline in its source saved and then did not load).
  for (const std::string& bad : {std::string("a\nb"), std::string(513, 'x')})
    CHECK_THROWS_WITH(HeuristicRegion(r.bounds(), r.dims(), r.probabilities(), r.threshold(), bad),
                      Contains("region source: must be one line of at most 512 bytes"));
  CHECK(HeuristicRegion::from_json(HeuristicRegion(r.bounds(), r.dims(), r.probabilities(), r.threshold(),
                                                   std::string(512, 'y')).to_json(), "r.json").source() == std::string(512, 'y'));
  // The offending threshold exactly (F3: 1.0000001 was shown as "got 1", in range to the eye).
  CHECK_THROWS_WITH(HeuristicRegion(r.bounds(), r.dims(), r.probabilities(), 1.0000001),
                    Contains("region threshold: must be in (0, 1], got 1.0000001"));
  // A cell outside the grid has no index (F9: (dims.x, 0, 0) answered the next row's first cell).
  const Eigen::Vector3i d = r.dims();
  CHECK(r.index(d.x() - 1, d.y() - 1, d.z() - 1) == r.probabilities().size() - 1);
  CHECK(r.coords(r.index(d.x() - 1, 0, 0)) == I(d.x() - 1, 0, 0));
  for (const Eigen::Vector3i& out : {I(d.x(), 0, 0), I(0, d.y(), 0), I(0, 0, d.z()), I(-1, 0, 0), I(0, -1, 0), I(0, 0, -1)})
    CHECK_THROWS_WITH(r.index(out.x(), out.y(), out.z()), Contains("lies outside the region's"));
  CHECK_THROWS_WITH(HeuristicRegion(Box{{0, 0, 0}, {1, 1, 1}}, I(8192, 8192, 1), {}, 0.5),
                    Contains("more than the limit"));
  // Dims whose product wraps 64 bits (2^31 - 1 cubed ~ 2^93; a wrapped product could pass a
  // size check) are refused, from a file and from the A*-dilated region alike.
  const int big = std::numeric_limits<int>::max();
  CHECK_THROWS_WITH(HeuristicRegion::cell_count(I(big, big, big)), Contains("more than the limit"));
  CHECK_THROWS_WITH(HeuristicRegion::cell_count(I(1 << 22, 1 << 21, 1 << 21)), Contains("more than the limit"));
  CHECK(HeuristicRegion::cell_count(I(32, 32, 32)) == 32768);
  // The limit itself is kept, one cell past it refused (held-out audit 7, h7-plan-06).
  CHECK(HeuristicRegion::cell_count(I(256, 256, 256)) == HeuristicRegion::kMaxCells);
  CHECK_THROWS_WITH(HeuristicRegion::cell_count(I(256, 256, 257)), Contains("more than the limit"));
  doc = r.to_json();
  doc["dims"] = {big, big, big};
  CHECK_THROWS_WITH(HeuristicRegion::from_json(doc, "r.json"), Contains("more than the limit"));
  CHECK_THROWS_WITH(HeuristicRegion::from_path(Box{{0, 0, 0}, {1, 1, 1}}, I(big, big, 4), {{0.5, 0.5, 0.5}}, 1, "t"),
                    Contains("more than the limit"));
  CHECK_THROWS_WITH(HeuristicRegion(Box{{0, 0, 0}, {0, 1, 1}}, I(1, 1, 1), {1.0}, 0.5), Contains("must exceed"));
  // A misspelt or unknown key is refused, not ignored (a "treshold" ran with the default).
  doc = r.to_json();
  doc["treshold"] = doc["threshold"];
  doc.erase("threshold");
  CHECK_THROWS_WITH(HeuristicRegion::from_json(doc, "r.json"), Contains("did you mean \"threshold\""));
  doc = r.to_json();
  doc["bounds"]["mid"] = 1;
  CHECK_THROWS_WITH(HeuristicRegion::from_json(doc, "r.json"), Contains("bounds") && Contains("mid"));
}

TEST_CASE("The A*-dilated region covers the path and its 3x3x3 neighbourhood", "[REQ-PLAN-005]") {
  const Box bounds{{0, 0, 0}, {10, 10, 10}};
  const std::vector<V> path{V(0.5, 0.5, 0.5), V(9.5, 0.5, 0.5)};  // along the x axis, first row of cells
  const HeuristicRegion r0 = HeuristicRegion::from_path(bounds, I(10, 10, 10), path, 0, "p");
  CHECK(r0.cells().size() == 10);
  const HeuristicRegion r1 = HeuristicRegion::from_path(bounds, I(10, 10, 10), path, 1, "p");
  CHECK(r1.cells().size() == 10 * 2 * 2);  // clipped at the map's corner: y, z in {0, 1}
  for (double x = 0.1; x < 10; x += 0.37) CHECK(r1.contains(V(x, 0.5, 0.5)));
  CHECK_FALSE(r1.contains(V(5, 2.5, 0.5)));
  CHECK_THROWS_WITH(HeuristicRegion::from_path(bounds, I(10, 10, 10), path, -1, "p"), Contains("dilation"));
  CHECK_THROWS_WITH(HeuristicRegion::from_path(bounds, I(10, 10, 10), {}, 1, "p"), Contains("no points"));
  // Fifteenth campaign F2: a path outside the bounds was clamped onto border cells it never
  // touches ((-5, 5.5, 5.5) -> (-1, 5.5, 5.5) gave cell (0, 5, 5)), and coordinates near 1e17
  // lost the cells crossed; a path on the bounds' faces is inside.
  for (const std::vector<V>& outside : {std::vector<V>{V(-5, 5.5, 5.5), V(-1, 5.5, 5.5)}, std::vector<V>{V(15, 5.5, 5.5)},
                                        std::vector<V>{V(0.5, 0.5, 0.5), V(9.5, 9.5, 11)},
                                        std::vector<V>{V(-1e17, 1, 1), V(1e17, 1, 1)}})
    CHECK_THROWS_WITH(HeuristicRegion::from_path(bounds, I(10, 10, 10), outside, 0, "p"),
                      Contains("lies outside the region's bounds"));
  CHECK(HeuristicRegion::from_path(bounds, I(10, 10, 10), {V(0, 0, 0), V(10, 10, 10)}, 0, "p").cells().size() == 10);
}

TEST_CASE("The A*-dilated region holds exactly the cells a path passes through", "[REQ-PLAN-005][REQ-HEUR-002]") {
  // Fourteenth campaign C2: walking each segment in quarter-cell steps missed cells it crossed
  // by less than a step (sim-1 at 32^3: 0.2165 m through cell (6, 8, 4)). Checked against an
  // independent slab test: a cell the segment runs through for a positive length is in the
  // region (dilation 0), and every cell of the region touches the path.
  const auto inside_length = [](const V& a, const V& b, const Box& box) {
    double t0 = 0.0, t1 = 1.0;
    for (int ax = 0; ax < 3; ++ax) {
      const double d = b[ax] - a[ax];
      if (d == 0.0) {
        if (a[ax] < box.min[ax] || a[ax] > box.max[ax]) return -1.0;
        continue;
      }
      double lo = (box.min[ax] - a[ax]) / d, hi = (box.max[ax] - a[ax]) / d;
      if (lo > hi) std::swap(lo, hi);
      t0 = std::max(t0, lo);
      t1 = std::min(t1, hi);
    }
    return t1 < t0 ? -1.0 : (t1 - t0) * (b - a).norm();
  };
  const auto check = [&](const Box& bounds, const I& dims, const std::vector<V>& path) {
    const HeuristicRegion r = HeuristicRegion::from_path(bounds, dims, path, 0, "p");
    const std::vector<std::size_t>& cells = r.cells();
    int missed = 0, stray = 0;
    for (std::size_t i = 0; i < r.probabilities().size(); ++i) {
      double longest = -1.0;
      for (std::size_t s = 0; s + 1 < path.size(); ++s) longest = std::max(longest, inside_length(path[s], path[s + 1], r.cell_box(i)));
      const bool in = std::binary_search(cells.begin(), cells.end(), i);
      // Crossed for more than rounding of the cell's faces: must be in; not touched at all: must not.
      if (longest > 1e-9 * r.cell_size().minCoeff() && !in) ++missed;
      if (longest < 0.0 && in) ++stray;
    }
    CHECK(missed == 0);
    CHECK(stray == 0);
  };
  // The campaign's segment on sim-1's grid.
  check(Box{{0, 0, 0}, {100, 100, 40}}, I(32, 32, 32), {V(21.75, 25.25, 6.25), V(22.25, 25.75, 5.75)});
  // Random polylines on grids of unequal cells, some points outside the bounds (clamped).
  miner::Rng rng(14, 0);
  for (int trial = 0; trial < 40; ++trial) {
    const I dims(1 + static_cast<int>(rng.uniform_index(12)), 1 + static_cast<int>(rng.uniform_index(12)),
                 1 + static_cast<int>(rng.uniform_index(6)));
    const Box bounds{{-1, 2, 0}, {7, 5, 3}};
    std::vector<V> path;
    for (int k = 0; k < 4; ++k) path.emplace_back(rng.uniform(-1, 7), rng.uniform(2, 5), rng.uniform(0, 3));
    INFO("trial " << trial);
    check(bounds, dims, path);
  }
}

TEST_CASE("A region must match the map's bounds and hold at least one cell", "[REQ-PLAN-008]") {
  const auto map = miner::testing::wall_with_door_map();  // bounds [0,10] x [0,10] x [0,3]
  const HeuristicRegion wrong = two_cells();
  CHECK_THROWS_WITH(wrong.require_matches(map, "planner miner"),
                    Contains("do not match the map's bounds") && Contains("(10, 10, 3)"));
  const HeuristicRegion empty(map.bounds(), I(2, 2, 2), std::vector<double>(8, 0.2), 0.5);
  CHECK_THROWS_WITH(empty.require_matches(map, "planner miner"), Contains("no cell with probability >= threshold"));
  // Sixteenth campaign F4: a region of another map with the same bounds planned without a word.
  // The A*-dilated region records its map's fingerprint; another map is refused, the same map
  // (rebuilt, or read back from the region's file) is not.
  const auto closed = miner::testing::closed_wall_map();
  REQUIRE(closed.bounds().min == map.bounds().min);
  REQUIRE(closed.bounds().max == map.bounds().max);
  const auto problem = miner::plan::PlanningProblem::make(map, V(2, 5, 1.5), V(8, 5, 1.5), 0.1);
  const HeuristicRegion own = miner::plan::astar_dilated_region(problem, miner::plan::astar_reference(problem), I(8, 8, 4), 1);
  CHECK(own.map_fingerprint() == map.fingerprint());
  CHECK_NOTHROW(own.require_matches(miner::testing::wall_with_door_map(), "planner miner"));
  CHECK_THROWS_WITH(own.require_matches(closed, "r.json"),
                    Contains("r.json: the region was built for another map (fingerprint ") && Contains("same bounds"));
  const HeuristicRegion back = HeuristicRegion::from_json(own.to_json(), "r.json");
  CHECK(back.map_fingerprint() == map.fingerprint());
  CHECK_THROWS_WITH(back.require_matches(closed, "r.json"), Contains("built for another map"));
  // A moved-from map is named as such, not as another map (seventeenth campaign F23).
  {
    auto source = miner::testing::wall_with_door_map();
    const auto moved_into = std::move(source);
    CHECK_NOTHROW(own.require_matches(moved_into, "r.json"));
    CHECK_THROWS_WITH(own.require_matches(source, "r.json"), Contains("r.json: the map was moved from") && !Contains("another map"));
  }
  // Without one (a region made from numbers, or an older file) the bounds are all it is checked by.
  miner::Json older = own.to_json();
  older.erase("map_fingerprint");
  CHECK_NOTHROW(HeuristicRegion::from_json(older, "r.json").require_matches(closed, "r.json"));
  for (const char* bad : {"0000000000000000", "ABCDEF0123456789", "12345"}) {
    miner::Json doc = own.to_json();
    doc["map_fingerprint"] = bad;
    CHECK_THROWS_WITH(HeuristicRegion::from_json(doc, "r.json"), Contains("r.json: map_fingerprint: must be 16 lower-case hexadecimal"));
  }
  CHECK_THROWS_AS(empty.sample(*std::make_unique<miner::Rng>(1)), miner::Error);
}

TEST_CASE("Hops through H enter cells whose probability equals the threshold", "[REQ-PLAN-005][REQ-PLAN-020]") {
  // H is p >= threshold (REQ-PLAN-005): a chain whose middle cells sit exactly on the threshold
  // (as the A*-dilated region's p = threshold = 1 does everywhere) still joins its ends.
  const HeuristicRegion r(Box{{0, 0, 0}, {4, 1, 1}}, I(4, 1, 1), {0.9, 0.5, 0.5, 0.9}, 0.5);
  REQUIRE(r.contains(V(1.5, 0.5, 0.5)));
  CHECK(r.hops_to(V(0.5, 0.5, 0.5)) == std::vector<int>{0, 1, 2, 3});
  CHECK(r.hops_to(V(3.5, 0.5, 0.5)) == std::vector<int>{3, 2, 1, 0});
  const HeuristicRegion ones(Box{{0, 0, 0}, {3, 1, 1}}, I(3, 1, 1), {1.0, 1.0, 1.0}, 1.0);
  CHECK(ones.hops_to(V(2.5, 0.5, 0.5)) == std::vector<int>{2, 1, 0});
}

TEST_CASE("Hops through H and a path's share in H are measured on the region's cells", "[REQ-PLAN-020]") {
  // 4 x 2 x 1 cells over [0,8] x [0,2] x [0,1]; H = cells 0, 1, 2 (the row y = 0, x < 6) and 7.
  std::vector<double> p(8, 0.0);
  for (int c : {0, 1, 2, 7}) p[static_cast<std::size_t>(c)] = 1.0;
  const HeuristicRegion r(Box{{0, 0, 0}, {8, 2, 1}}, I(4, 2, 1), p, 0.5);
  CHECK(r.cell_at(V(0.5, 0.5, 0.5)) == 0);
  CHECK(r.cell_at(V(8, 2, 1)) == 7);  // the max faces belong to the last cells
  CHECK(r.cell_at(V(8.5, 0.5, 0.5)) == -1);
  // From cell 0: 1 and 2 by chain, 7 = (3, 1) touches 2 = (2, 0) at a corner edge.
  CHECK(r.hops_to(V(0.5, 0.5, 0.5)) == std::vector<int>{0, 1, 2, -1, -1, -1, -1, 3});
  // The source cell counts as in H even when it is not; cells off H are never entered.
  CHECK(r.hops_to(V(0.5, 1.5, 0.5)) == std::vector<int>{1, 1, 2, -1, 0, -1, -1, 3});
  CHECK(r.hops_to(V(9, 0, 0)) == std::vector<int>(8, -1));
  // A path along y = 0.5 from x = 0 to 8: cells 0-2 hold 6 of its 8 m.
  CHECK(r.length_fraction_inside({V(0, 0.5, 0.5), V(8, 0.5, 0.5)}) == Approx(0.75));
  CHECK(r.length_fraction_inside({V(0, 1.5, 0.5), V(6, 1.5, 0.5)}) == 0.0);
  CHECK(r.length_fraction_inside({V(0, 1.5, 0.5), V(6, 1.5, 0.5), V(6, 0.5, 0.5), V(6.5, 1.5, 0.5)}) > 0.0);
  CHECK(r.length_fraction_inside({V(1, 1, 1)}) == 0.0);
  // Each step counts by its midpoint, so one crossing of H's boundary errs by at most half a
  // step: from x = 6.1 (outside) to 0, 25 steps of 0.244 m, exactly 6 / 6.1 inside (held-out
  // audit 7, h7-plan-05 counted a step by its start: 0.96, off by a whole step).
  const double exact = 6.0 / 6.1, half_step = 0.5 * (6.1 / 25.0) / 6.1;
  CHECK(std::abs(r.length_fraction_inside({V(6.1, 0.5, 0.5), V(0, 0.5, 0.5)}) - exact) <= half_step + 1e-12);
  CHECK(std::abs(r.length_fraction_inside({V(0, 0.5, 0.5), V(6.1, 0.5, 0.5)}) - exact) <= half_step + 1e-12);
  // Fifteenth campaign F8: length outside the bounds counts as outside, walked only where cells
  // are (a segment to x = 1e300 gave NaN after ~1e300 steps), and a point that is not finite is
  // refused (a NaN point gave 0).
  CHECK(r.length_fraction_inside({V(0, 0.5, 0.5), V(16, 0.5, 0.5)}) == Approx(6.0 / 16.0));
  CHECK(r.length_fraction_inside({V(-8, 0.5, 0.5), V(8, 0.5, 0.5)}) == Approx(6.0 / 16.0));
  CHECK(r.length_fraction_inside({V(0, 0.5, 0.5), V(1e300, 0.5, 0.5)}) == Approx(6e-300).epsilon(1e-9));
  CHECK(r.length_fraction_inside({V(0, 0.5, -3), V(8, 0.5, -3)}) == 0.0);  // beside the bounds
  CHECK_THROWS_WITH(r.length_fraction_inside({V(0, 0.5, 0.5), V(NAN, 0.5, 0.5)}),
                    Contains("length_fraction_inside: path point 1") && Contains("is not finite"));
  CHECK_THROWS_WITH(r.length_fraction_inside({V(-1e308, 0.5, 0.5), V(1e308, 0.5, 0.5)}),
                    Contains("segment 0") && Contains("has no finite length"));
  CHECK_THROWS_WITH(r.length_fraction_inside({V(0, 0, 0), V(1e308, 0, 0), V(0, 0, 0)}),
                    Contains("the path's length overflows a double"));
}
