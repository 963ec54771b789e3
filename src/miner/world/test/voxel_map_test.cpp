#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>

#include "miner/core/error.hpp"
#include "miner/core/json_io.hpp"
#include "miner/core/sha256.hpp"
#include "miner/world/map.hpp"
#include "miner/world/octree_io.hpp"
#include "miner/world/voxel_grid.hpp"
#include "test_maps.hpp"

using namespace miner::world;
using Catch::Matchers::Contains;
using V = Eigen::Vector3d;

namespace {

/// 4 x 4 x 4 voxels of 1 m from the origin: (1, 1, 1) unknown, (2, 2, 2) occupied, the rest free.
std::shared_ptr<const VoxelLayer> small_layer() {
  std::vector<std::uint8_t> states(64, static_cast<std::uint8_t>(VoxelState::kFree));
  states[(1 * 4 + 1) * 4 + 1] = static_cast<std::uint8_t>(VoxelState::kUnknown);
  states[(2 * 4 + 2) * 4 + 2] = static_cast<std::uint8_t>(VoxelState::kOccupied);
  return std::make_shared<const VoxelLayer>(Eigen::Vector3i::Zero(), 1.0, Eigen::Vector3i(4, 4, 4), std::move(states));
}

}  // namespace

TEST_CASE("Unknown space blocks by default and is free only on request", "[REQ-WORLD-013]") {
  const Map map = Map::from_voxels({small_layer(), UnknownPolicy::kOccupied, "", ""});
  const V in_unknown(1.5, 1.5, 1.5), in_occupied(2.5, 2.5, 2.5), in_free(0.5, 3.5, 0.5);
  CHECK(map.point_collision(in_unknown));
  CHECK(map.point_collision(in_occupied));
  CHECK_FALSE(map.point_collision(in_free));
  CHECK_THROWS_WITH(map.require_free(in_unknown, 0.0, "start"), Contains("start (1.5, 1.5, 1.5) lies inside unknown voxel (1, 1, 1)"));
  CHECK(VoxelGrid(map, 0.0).occupied(Eigen::Vector3i(1, 1, 1)));

  const Map open = map.with_unknown(UnknownPolicy::kFree);
  CHECK_FALSE(open.point_collision(in_unknown));
  CHECK(open.point_collision(in_occupied));
  CHECK_FALSE(VoxelGrid(open, 0.0).occupied(Eigen::Vector3i(1, 1, 1)));
  CHECK(open.segment_free(V(0.5, 0.5, 0.5), V(1.5, 1.5, 1.5)));
  CHECK_FALSE(map.segment_free(V(0.5, 0.5, 0.5), V(1.5, 1.5, 1.5)));
  CHECK_THROWS_WITH(parse_unknown_policy("maybe", "--unknown"), Contains("--unknown: unknown-space policy \"maybe\""));
}

TEST_CASE("A map file references its voxels by path and SHA-256", "[REQ-WORLD-015][REQ-WORLD-013]") {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(test::temp_path("refs")) / "";
  fs::create_directories(dir);
  write_octree_bt(*small_layer(), (dir / "small.bt").string());
  const auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream((dir / name).string()) << text;
    return (dir / name).string();
  };
  const Map loaded = Map::load(write("ok.json", R"({"format": "miner-map-v1", "voxels": {"file": "small.bt", "unknown": "free"}})"));
  REQUIRE(loaded.voxels() != nullptr);
  CHECK(loaded.voxel_source()->file == fs::absolute(dir / "small.bt").lexically_normal().string());
  CHECK(loaded.voxel_source()->sha256 == miner::sha256_hex(miner::read_file_bytes((dir / "small.bt").string())));
  CHECK(loaded.voxels()->policy() == UnknownPolicy::kFree);
  CHECK(loaded.bounds().max == V(4, 4, 4));
  CHECK(loaded.resolution() == 1.0);
  // The written document references the file (no copy of the voxels) and reads back the same.
  const miner::Json doc = loaded.to_json();
  CHECK(doc["voxels"]["sha256"] == loaded.voxel_source()->sha256);
  CHECK(Map::from_json(doc, (dir / "again.json").string()).to_json() == doc);
  // A changed file is refused by its hash; bad fields are named.
  miner::Json stale = doc;
  stale["voxels"]["sha256"] = std::string(64, '0');
  CHECK_THROWS_WITH(Map::from_json(stale, "stale.json"), Contains("voxels.sha256") && Contains("the file changed"));
  CHECK_THROWS_WITH(Map::load(write("policy.json", R"({"format": "miner-map-v1", "voxels": {"file": "small.bt", "unknown": "maybe"}})")),
                    Contains("policy.json: voxels.unknown: unknown-space policy \"maybe\"") && !Contains("unknown: unknown:"));
  // What the voxel file is comes before its hash: a point cloud is named as not an OctoMap
  // (issue 20, fourth campaign: blamed on the hash).
  write("cloud.ply", "ply\nformat ascii 1.0\nelement vertex 0\nend_header\n");
  CHECK_THROWS_WITH(Map::load(write("cloud-ref.json", R"({"format": "miner-map-v1", "voxels": {"file": "cloud.ply",
                                                          "sha256": "0000000000000000000000000000000000000000000000000000000000000000"}})")),
                    Contains("cloud.ply") && !Contains("sha256"));
  CHECK_THROWS_WITH(Map::load(write("empty-ref.json", R"({"format": "miner-map-v1", "voxels": {"file": ""}})")),
                    Contains("empty-ref.json: voxels.file: is empty"));
  CHECK_THROWS_WITH(Map::load(write("upper-ref.json", R"({"format": "miner-map-v1", "voxels": {"file": "small.bt", "sha256": "ABC"}})")),
                    Contains("upper-ref.json: voxels.sha256: must be 64 lower-case hexadecimal digits"));
  // Formats read elsewhere are named, not reported as malformed JSON.
  std::filesystem::copy_file(dir / "small.bt", dir / "upper.BT", std::filesystem::copy_options::overwrite_existing);
  CHECK_THROWS_WITH(Map::load((dir / "upper.BT").string()), Contains("upper.BT: is an OctoMap file") && Contains("rename it"));
  CHECK_THROWS_WITH(Map::load((dir / "cloud.ply").string()), Contains("cloud.ply: is a point cloud") && Contains("map import"));
  CHECK_THROWS_WITH(Map::load(write("key.json", R"({"format": "miner-map-v1", "voxels": {"files": "small.bt"}})")),
                    Contains("files") && Contains("did you mean"));
  CHECK_THROWS_WITH(Map::load(write("gone.json", R"({"format": "miner-map-v1", "voxels": {"file": "gone.bt"}})")),
                    Contains("gone.json: voxels.file: ") && Contains("gone.bt: cannot open"));
  // A voxel file that is a device or a folder is named through the map and its field (issue 20,
  // sixth campaign U4: "/dev/zero: cannot open voxel file" named neither).
  CHECK_THROWS_WITH(Map::load(write("dev.json", R"({"format": "miner-map-v1", "voxels": {"file": "/dev/zero"}})")),
                    Contains("dev.json: voxels.file: /dev/zero:"));
  CHECK_THROWS_WITH(Map::load(write("dir.json", R"({"format": "miner-map-v1", "voxels": {"file": "."}})")),
                    Contains("dir.json: voxels.file: "));
  CHECK_THROWS_WITH(Map::load(write("text-ref.json", R"({"format": "miner-map-v1", "voxels": {"file": "text-ref.json"}})")),
                    Contains("text-ref.json: voxels.file: ") && Contains("OctoMap"));
  CHECK_THROWS_WITH(
      Map::load(write("lattice.json", R"({"format": "miner-map-v1", "bounds": {"min": [0.5, 0, 0], "max": [4, 4, 4]},
                                          "resolution": 1, "obstacles": [], "voxels": {"file": "small.bt"}})")),
      Contains("bounds.min[0] = 0.5 is not a multiple of the voxels' resolution"));
  // Bounds past the voxels hold space never observed: unknown, so refused while unknown is
  // occupied (the queries would answer it free: issue 20, fourth campaign planned through it);
  // with "unknown": "free" it is free as asked.
  CHECK_THROWS_WITH(
      Map::load(write("wide.json", R"({"format": "miner-map-v1", "bounds": {"min": [0, 0, 0], "max": [6, 4, 4]},
                                       "resolution": 1, "voxels": {"file": "small.bt"}})")),
      Contains("wide.json: bounds: [(0, 0, 0) - (6, 4, 4)] reaches beyond the voxels [(0, 0, 0) - (4, 4, 4)]"));
  const Map wide = Map::load(write("wide-free.json", R"({"format": "miner-map-v1", "bounds": {"min": [0, 0, 0], "max": [6, 4, 4]},
                                       "resolution": 1, "voxels": {"file": "small.bt", "unknown": "free"}})"));
  CHECK_FALSE(wide.point_collision(V(5.5, 2, 2)));
  // Boxes and voxels obstruct together.
  const Map both = Map::load(write("both.json", R"({"format": "miner-map-v1", "obstacles": [{"type": "box", "min": [0, 3, 0], "max": [1, 4, 1]}],
                                                   "voxels": {"file": "small.bt"}})"));
  CHECK(both.point_collision(V(0.5, 3.5, 0.5)));
  CHECK(both.point_collision(V(2.5, 2.5, 2.5)));
  CHECK(both.point_collision(V(1.5, 1.5, 1.5)));  // unknown: occupied by default
}

TEST_CASE("Segments reaching far beyond a voxel map get the answer of their part over it", "[REQ-WORLD-005][REQ-WORLD-013]") {
  // The walk along a segment is clipped to the layer's bounds grown by the radius (issue 20: 10
  // km segments over a 4 m map were walked voxel by voxel); the answers are those of the part
  // over the map, the radius reaching across the clip included.
  const Map map = Map::from_voxels({small_layer(), UnknownPolicy::kOccupied, "", ""});
  const double far = 1e4;
  CHECK(map.segment_collision(V(2.5, 2.5, -far), V(2.5, 2.5, far)));                      // through (2, 2, 2)
  CHECK_FALSE(map.segment_collision(V(-far, 3.5, 0.5), V(far, 3.5, 0.5)));                // a free row
  CHECK(map.segment_collision(V(0.5, 0.5, 0.5), V(0.5, 0.5, 0.5) + far * V(1, 1, 1).normalized()));  // unknown (1,1,1)
  // Passing 1.3 m above the occupied voxel's top face (z = 3), outside the map's z range: the
  // radius decides, as it does for the short segment over the map.
  for (double radius : {1.0, 1.5}) {
    INFO("radius " << radius);
    const bool near = map.segment_collision(V(2.5, 2.5, 4.3) - far * V(1, 0, 0), V(2.5, 2.5, 4.3) + far * V(1, 0, 0), radius).has_value();
    const bool over = map.segment_collision(V(-1, 2.5, 4.3), V(5, 2.5, 4.3), radius).has_value();
    CHECK(near == over);
    CHECK(near == (radius > 1.3));
  }
  // Entirely beside the map, beyond the radius: free.
  CHECK_FALSE(map.segment_collision(V(-far, -5, -5), V(far, -5, -5), 1.0));
}

TEST_CASE("A voxel map's grid grows a blocked voxel by the robot radius: cubes that only touch stay free",
          "[REQ-WORLD-006][REQ-WORLD-012]") {
  // A cell is occupied iff its open interior comes within r of a blocked voxel's cube: with
  // r = 0 a neighbour only touches it (held-out audit 6, h6-world-04 took distance 0 as
  // meeting at r = 0: every neighbour blocked).
  const Map open = Map::from_voxels({small_layer(), UnknownPolicy::kFree, "", ""});
  const VoxelGrid bare(open, 0.0);
  CHECK(bare.occupied_count() == 1);
  CHECK(bare.occupied(Eigen::Vector3i(2, 2, 2)));
  // r just under a cell: the 26 neighbours (cube distance 0) join, a cell one gap away
  // (distance 1) does not; at r = 1 it does (the rounding slack on r^2 errs towards occupied).
  const VoxelGrid under(open, 1.0 - 1e-6);
  CHECK(under.occupied_count() == 27);
  CHECK_FALSE(under.occupied(Eigen::Vector3i(0, 2, 2)));
  CHECK(VoxelGrid(open, 1.0).occupied(Eigen::Vector3i(0, 2, 2)));
}
