// The "scan" family (REQ-WORLD-019): maps as a mapping run leaves them.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <set>

#include "miner/core/error.hpp"
#include "miner/core/json_io.hpp"
#include "miner/core/sha256.hpp"
#include "miner/world/astar.hpp"
#include "miner/world/map_generator.hpp"
#include "miner/world/octree_io.hpp"
#include "miner/world/voxel_grid.hpp"

using namespace miner::world;

namespace {

/// Small bases keep the sanitizer build quick; the generator is the same at every size.
GeneratorOverrides small(const std::string& base) {
  GeneratorOverrides o;
  o.base = base;
  if (base == "sim" || base == "indoor") return o;
  o.size = Eigen::Vector3d(20, 16, base == "multilevel" ? 7 : 4);
  o.resolution = 0.25;
  return o;
}

std::string bt_bytes(const Map& m) { return octree_bt_bytes(*m.voxel_source()->layer); }

}  // namespace

TEST_CASE("A scan map holds only the run's voxels: free, occupied and unknown, the query free and solvable", "[REQ-WORLD-019]") {
  const GeneratorPreset p = generator_preset("scan");
  // The four families that take a size (sim and indoor are fixed-size worlds; their scans are
  // the same code over a bigger map, run by `miner map gen --preset scan` in the golden).
  for (const std::string base : {"rooms", "cluttered", "forest", "multilevel"}) {
    INFO("base " << base);
    const Map map = generate_map(p, 1, small(base));
    REQUIRE(map.voxels());
    CHECK(map.obstacles().empty());  // the world's boxes are not in the scan
    const VoxelLayer& layer = map.voxels()->layer();
    CHECK(layer.count(VoxelState::kFree) > 0);
    CHECK(layer.count(VoxelState::kOccupied) > 0);
    CHECK(layer.count(VoxelState::kUnknown) > 0);  // the run did not see everything
    CHECK(map.voxel_source()->unknown == UnknownPolicy::kOccupied);
    const Query& q = *map.query();
    CHECK(q.robot_radius == p.robot_radius);
    CHECK(map.is_free(q.start, q.robot_radius));
    CHECK(map.is_free(q.goal, q.robot_radius));
    const VoxelGrid grid(map, q.robot_radius);
    const GridPath path = astar(map, grid, q.start, q.goal);
    for (std::size_t i = 1; i < path.points.size(); ++i)
      CHECK(map.segment_free(path.points[i - 1], path.points[i], q.robot_radius));
    // The same world read with unknown space free is at least as open: every path stays free.
    const Map optimistic = map.with_unknown(UnknownPolicy::kFree);
    for (std::size_t i = 1; i < path.points.size(); ++i)
      CHECK(optimistic.segment_free(path.points[i - 1], path.points[i], q.robot_radius));
  }
}

TEST_CASE("Scan maps repeat their bytes for a seed, differ across seeds and draw their base", "[REQ-WORLD-019]") {
  const GeneratorPreset p = generator_preset("scan");
  const Map a = generate_map(p, 3, small("rooms"));
  const Map b = generate_map(p, 3, small("rooms"));
  CHECK(bt_bytes(a) == bt_bytes(b));
  CHECK(a.query()->start == b.query()->start);
  CHECK(a.query()->goal == b.query()->goal);
  CHECK(bt_bytes(generate_map(p, 4, small("rooms"))) != bt_bytes(a));
  // Without --base the base is drawn per seed: within a few seeds more than one appears, and
  // the ScanMap names the one drawn (a small size keeps the draw among the four families).
  GeneratorOverrides drawn;
  drawn.size = Eigen::Vector3d(16, 12, 4);
  drawn.resolution = 0.25;
  std::set<std::string> bases;
  for (std::uint64_t seed = 1; seed <= 12 && bases.size() < 2; ++seed) {
    const ScanMap s = generate_scan_map(p, seed, drawn);
    CHECK(std::string("cluttered rooms forest multilevel").find(s.base) != std::string::npos);
    bases.insert(s.base);
  }
  CHECK(bases.size() >= 2);
}

TEST_CASE("A scan map saved as JSON writes its voxels beside it and loads back the same", "[REQ-WORLD-019][REQ-WORLD-015]") {
  namespace fs = std::filesystem;
  const Map map = generate_map(generator_preset("scan"), 2, small("cluttered"));
  const fs::path dir = fs::temp_directory_path() / "miner-scan-family-test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string json = (dir / "scan.json").string();
  map.save(json);
  const nlohmann::json doc = miner::read_json_file(json);
  // Named by content: scan.<first 16 hex digits of its SHA-256>.bt (seventeenth campaign F9).
  const std::string name = doc["voxels"]["file"].get<std::string>();
  CHECK(name == "scan." + doc["voxels"]["sha256"].get<std::string>().substr(0, 16) + ".bt");
  REQUIRE(fs::exists(dir / name));
  // The file beside it: the layer's OctoMap bytes with the save's mark after the header line.
  const std::string side = miner::read_file_bytes((dir / name).string());
  CHECK(doc["voxels"]["sha256"] == miner::sha256_hex(side));
  std::string unmarked = side;
  const std::size_t mark = unmarked.find('\n') + 1;
  CHECK(unmarked.compare(mark, 18, "# MINER Map::save:") == 0);
  unmarked.erase(mark, unmarked.find('\n', mark) + 1 - mark);
  CHECK(unmarked == bt_bytes(map));
  const Map back = Map::load(json);
  CHECK(bt_bytes(back) == bt_bytes(map));
  CHECK(back.query()->start == map.query()->start);
  CHECK(back.query()->goal == map.query()->goal);
  CHECK(back.bounds().min == map.bounds().min);
  CHECK(back.bounds().max == map.bounds().max);
  // An unsaved voxel map has no file to reference: to_json refuses rather than write "".
  CHECK_THROWS_WITH(map.to_json(), Catch::Contains("save"));
  fs::remove_all(dir);
}

TEST_CASE("A scan saved again never replaces voxels that other map files name, and a linked JSON keeps its pair together",
          "[REQ-WORLD-019][REQ-CORE-004]") {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / "miner-scan-family-resave";
  fs::remove_all(dir);
  fs::create_directories(dir / "other");
  const std::string json = (dir / "s.json").string();
  const Map first = generate_map(generator_preset("scan"), 1, small("rooms"));
  first.save(json);
  // Another map file naming the first scan's voxels (as `map convert` or a run folder's map.json
  // does): absolute path and SHA-256.
  const std::string keep = (dir / "keep.json").string();
  Map::load(json).save(keep);
  const std::string first_voxels = miner::read_json_file(json)["voxels"]["file"].get<std::string>();
  // Seventeenth campaign F9: a scan of another seed saved to the same JSON replaced s.bt, and
  // keep.json stopped loading. Now the second scan's voxels go to their own file.
  const Map second = generate_map(generator_preset("scan"), 3, small("rooms"));
  REQUIRE(bt_bytes(second) != bt_bytes(first));
  second.save(json);
  const std::string second_voxels = miner::read_json_file(json)["voxels"]["file"].get<std::string>();
  CHECK(second_voxels != first_voxels);
  CHECK(fs::exists(dir / first_voxels));
  CHECK(bt_bytes(Map::load(keep)) == bt_bytes(first));
  CHECK(bt_bytes(Map::load(json)) == bt_bytes(second));
  // The same save again: the same file, left as it is.
  second.save(json);
  CHECK(miner::read_json_file(json)["voxels"]["file"] == second_voxels);
  // A file a user put under the name a save would take, with other bytes, is refused, not replaced.
  const std::string third = (dir / "t.json").string();
  const fs::path taken = dir / ("t" + second_voxels.substr(1));
  std::ofstream(taken) << "someone else's OctoMap";
  CHECK_THROWS_WITH(second.save(third), Catch::Contains(taken.string()) && Catch::Contains("not replaced"));
  CHECK(miner::read_file_bytes(taken.string()) == "someone else's OctoMap");
  CHECK_FALSE(fs::exists(third));
  // Seventeenth campaign F32: a JSON output that is a link is written into its target, and the
  // voxels now go beside the target, so the map loads by either name.
  std::ofstream(dir / "other" / "Y.json") << "{}";
  fs::create_symlink(dir / "other" / "Y.json", dir / "X.json");
  first.save((dir / "X.json").string());
  CHECK(fs::is_symlink(dir / "X.json"));
  const std::string linked = miner::read_json_file((dir / "other" / "Y.json").string())["voxels"]["file"].get<std::string>();
  CHECK(fs::exists(dir / "other" / linked));
  CHECK(linked.rfind("Y.", 0) == 0);
  CHECK(bt_bytes(Map::load((dir / "other" / "Y.json").string())) == bt_bytes(first));
  CHECK(bt_bytes(Map::load((dir / "X.json").string())) == bt_bytes(first));
  // Eighteenth campaign F21: a map read from a JSON whose voxel file was then deleted (or
  // changed) saved a JSON naming the missing file. Refused, naming voxels.file.
  const Map loaded = Map::load(keep);
  const std::string named = miner::read_json_file(keep)["voxels"]["file"].get<std::string>();
  fs::remove(named);
  CHECK_THROWS_WITH(loaded.save((dir / "again.json").string()), Catch::Contains("voxels.file: " + named));
  CHECK_FALSE(fs::exists(dir / "again.json"));
  CHECK_NOTHROW(loaded.save((dir / "again.bt").string()));  // the voxels themselves: still in memory
  // Nineteenth campaign F5: a .json name linked to a .bt file got JSON written into the .bt.
  fs::create_symlink("x.bt", dir / "b.json");
  CHECK_THROWS_WITH(first.save((dir / "b.json").string()), Catch::Contains("b.json: a symbolic link to") &&
                                                               Catch::Contains("whose suffix is not the link's"));
  CHECK_FALSE(fs::exists(dir / "x.bt"));
  fs::remove_all(dir);
}

TEST_CASE("Scan generator errors: an unknown base, a base that takes no size", "[REQ-WORLD-019]") {
  const GeneratorPreset p = generator_preset("scan");
  GeneratorOverrides o;
  o.base = "scan";
  CHECK_THROWS_WITH(generate_map(p, 1, o), Catch::Contains("base") && Catch::Contains("rooms"));
  o.base = "nowhere";
  CHECK_THROWS_WITH(generate_map(p, 1, o), Catch::Contains("base"));
  o.base = "sim";
  o.size = Eigen::Vector3d(20, 20, 5);
  CHECK_THROWS_WITH(generate_map(p, 1, o), Catch::Contains("size"));
  GeneratorOverrides other;
  other.base = "rooms";
  CHECK_THROWS_WITH(generate_map(generator_preset("forest"), 1, other), Catch::Contains("base"));
}
