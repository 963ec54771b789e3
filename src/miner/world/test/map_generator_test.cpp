#include <catch2/catch.hpp>

#include "miner/core/error.hpp"
#include "miner/core/json_io.hpp"
#include "miner/world/astar.hpp"
#include "miner/world/map_generator.hpp"
#include "miner/world/voxel_grid.hpp"

using namespace miner::world;
using Catch::Matchers::Contains;

TEST_CASE("The same preset and seed give the same bytes and another seed another map", "[REQ-WORLD-009]") {
  for (const std::string name : {"sim", "indoor"}) {
    INFO(name);
    const auto p = generator_preset(name);
    const std::string a = miner::dump_json(generate_map(p, 11).to_json());
    const std::string b = miner::dump_json(generate_map(p, 11).to_json());
    const std::string c = miner::dump_json(generate_map(p, 12).to_json());
    CHECK(a == b);
    CHECK(a != c);
  }
}

TEST_CASE("Sim maps follow the paper's simulation set-up and their query is solvable", "[REQ-WORLD-009]") {
  const auto p = generator_preset("sim");
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const Map map = generate_map(p, seed);
    CHECK(map.bounds().max == Eigen::Vector3d(100, 100, 40));
    CHECK(map.obstacles().size() >= 45);
    CHECK(map.obstacles().size() <= 60);
    for (const Box& b : map.obstacles()) {
      for (int k = 0; k < 3; ++k) {
        CHECK(b.extent()[k] >= 4.0 - 0.1);  // sides quantised to 0.1 m
        CHECK(b.extent()[k] <= 15.0 + 0.1);
      }
      CHECK(map.bounds().contains(b.min));
      CHECK(map.bounds().contains(b.max));
    }
    REQUIRE(map.query());
    const VoxelGrid grid(map, map.query()->robot_radius);
    CHECK_NOTHROW(astar(map, grid, map.query()->start, map.query()->goal));
  }
}

TEST_CASE("Indoor maps: 15-20 pillars of 0.6 x 1.2 m on the floor and a 1 m hoop", "[REQ-WORLD-009]") {
  const Map map = generate_map(generator_preset("indoor"), 5);
  CHECK(map.bounds().max == Eigen::Vector3d(10, 10, 5));
  int pillars = 0, hoop_parts = 0;
  for (const Box& b : map.obstacles()) {
    const Eigen::Vector3d e = b.extent();
    const bool footprint = (std::abs(e.x() - 0.6) < 1e-9 && std::abs(e.y() - 1.2) < 1e-9) ||
                           (std::abs(e.x() - 1.2) < 1e-9 && std::abs(e.y() - 0.6) < 1e-9);
    if (footprint) {
      ++pillars;
      CHECK(b.min.z() == 0.0);
      CHECK(b.max.z() >= 1.5 - 0.05);
    } else {
      ++hoop_parts;
    }
  }
  CHECK(pillars >= 15);
  CHECK(pillars <= 20);
  CHECK(hoop_parts == 17);  // 16 bars of the ring and its post
}

TEST_CASE("Generator input errors: unknown preset, negative count, impossible clutter", "[REQ-WORLD-009]") {
  CHECK_THROWS_WITH(generator_preset("forest"), Contains("unknown map preset \"forest\" (known: sim, indoor)"));
  CHECK_THROWS_WITH(generate_map(generator_preset("sim"), 1, -3), Contains("obstacles: count must not be negative"));
  const Map empty = generate_map(generator_preset("sim"), 1, 0);
  CHECK(empty.obstacles().empty());
  // A robot too large for the clutter: every attempt is unsolvable, so the generator
  // gives up after kMaxGeneratorAttempts with NoSolution instead of looping.
  GeneratorPreset cramped = generator_preset("sim");
  cramped.bounds = Box{{0, 0, 0}, {20, 20, 10}};
  cramped.start_region = Box{{1, 1, 1}, {2, 2, 2}};
  cramped.goal_region = Box{{18, 18, 1}, {19, 19, 2}};
  cramped.keep_free = 0.5;
  cramped.robot_radius = 4.0;
  CHECK_THROWS_WITH(generate_map(cramped, 1, 30), Contains("no solvable map in 16 attempts for seed 1"));
}
