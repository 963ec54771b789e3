// Goldens of the world capability: generated maps and A* on them, and the fixture
// maps in fixtures/maps/ regenerate byte for byte from their preset and seed.
#include <catch2/catch.hpp>

#include <fstream>
#include <sstream>

#include "miner/core/json_io.hpp"
#include "miner/core/sha256.hpp"
#include "miner/testing/golden.hpp"
#include "miner/world/astar.hpp"
#include "miner/world/map_generator.hpp"
#include "miner/world/octree_io.hpp"
#include "miner/world/voxel_grid.hpp"

using namespace miner::world;

namespace {

nlohmann::json astar_summary(const Map& map) {
  const VoxelGrid grid(map, map.query()->robot_radius);
  const GridPath path = astar(map, grid, map.query()->start, map.query()->goal);
  nlohmann::json cells = nlohmann::json::array();
  for (const auto& c : path.cells) cells.push_back({c.x(), c.y(), c.z()});
  return {{"cost", path.cost}, {"grid_cost", path.grid_cost}, {"expanded", path.expanded},
          {"occupied_cells", grid.occupied_count()}, {"cells", cells}};
}

std::string fixture_path(const std::string& name) {
  const char* env = std::getenv("MINER_SOURCE_DIR");
  return std::string(env && *env ? env : MINER_SOURCE_DIR) + "/fixtures/maps/" + name;
}

}  // namespace

TEST_CASE("Generated maps and their A* paths match the goldens", "[REQ-WORLD-009][REQ-WORLD-011][REQ-WORLD-020][REQ-WORLD-007][REQ-HARNESS-002]") {
  // Map coordinates are quantised decimals (exact match); path costs are sums of a few
  // hundred terms (abs 1e-9 m covers a different summation order).
  const miner::testing::Tolerance tol{1e-9, 0.0};
  for (const auto& [preset, seed] : std::vector<std::pair<std::string, std::uint64_t>>{{"sim", 1}, {"indoor", 1}, {"cluttered", 1}, {"rooms", 1}, {"forest", 3}, {"multilevel", 3}, {"mixed", 1}}) {
    const Map map = generate_map(generator_preset(preset), seed);
    const nlohmann::json actual = {{"map", map.to_json()}, {"astar", astar_summary(map)}};
    MINER_REQUIRE_GOLDEN("world/" + preset + "-seed-" + std::to_string(seed) + ".json", actual, tol);
  }
}

TEST_CASE("Fixture maps regenerate byte for byte from their preset and seed", "[REQ-WORLD-009]") {
  // fixtures/maps/<preset>-<seed>.json was written by `miner map gen --preset P --seed S`.
  for (const auto& [preset, seed] : std::vector<std::pair<std::string, int>>{
           {"sim", 1}, {"sim", 2}, {"sim", 3}, {"indoor", 1}, {"indoor", 2}}) {
    const std::string path = fixture_path(preset + "-" + std::to_string(seed) + ".json");
    INFO(path);
    std::ifstream in(path);
    REQUIRE(in);
    std::stringstream ss;
    ss << in.rdbuf();
    CHECK(ss.str() == miner::dump_json(generate_map(generator_preset(preset), static_cast<std::uint64_t>(seed)).to_json()));
  }
  // fixtures/maps/indoor-1.bt was written by `miner map convert --in indoor-1.json --out indoor-1.bt`.
  std::ifstream bt(fixture_path("indoor-1.bt"), std::ios::binary);
  std::stringstream bytes;
  bytes << bt.rdbuf();
  CHECK(bytes.str() == miner::world::octree_bt_bytes(generate_map(generator_preset("indoor"), 1).to_voxel_layer()));
}

TEST_CASE("A scan map, its mapping run and its A* path match the golden", "[REQ-WORLD-019][REQ-HARNESS-002]") {
  // A tripwire over the whole scan pipeline (base map, tour, sensor draw, ray casting, OctoMap
  // bytes): the voxels are compared by the sha256 of their .bt bytes, the rest as numbers.
  const miner::testing::Tolerance tol{1e-9, 0.0};
  GeneratorOverrides o;
  o.base = "rooms";
  o.size = Eigen::Vector3d(20, 16, 4);
  o.resolution = 0.25;
  const ScanMap scan = generate_scan_map(generator_preset("scan"), 1, o);
  const Map& map = scan.map;
  const VoxelLayer& layer = map.voxels()->layer();
  const ScanOptions& s = scan.sensor;
  const nlohmann::json actual = {
      {"base", scan.base},
      {"sensor", {{"range", s.range}, {"h_fov_deg", s.h_fov_deg}, {"v_fov_deg", s.v_fov_deg}, {"h_rays", s.h_rays},
                  {"v_rays", s.v_rays}, {"noise", s.noise}, {"dropout", s.dropout}, {"spacing", s.spacing}}},
      {"bounds", {{"min", miner::vec3_json(map.bounds().min)}, {"max", miner::vec3_json(map.bounds().max)}}},
      {"resolution", map.resolution()},
      {"query", {{"start", miner::vec3_json(map.query()->start)}, {"goal", miner::vec3_json(map.query()->goal)}}},
      {"voxels", {{"free", layer.count(VoxelState::kFree)}, {"occupied", layer.count(VoxelState::kOccupied)},
                  {"unknown", layer.count(VoxelState::kUnknown)}, {"bt_sha256", miner::sha256_hex(octree_bt_bytes(layer))}}},
      {"astar", astar_summary(map)}};
  MINER_REQUIRE_GOLDEN("world/scan-rooms-seed-1.json", actual, tol);
}
