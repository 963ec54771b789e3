#include <catch2/catch.hpp>

#include <cstring>
#include <filesystem>
#include <limits>

#include <fstream>
#include <functional>
#include <sstream>

#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>

#include "miner/core/error.hpp"
#include "miner/core/json_io.hpp"
#include "miner/core/rng.hpp"
#include "miner/world/map.hpp"
#include "miner/world/octree_io.hpp"
#include "test_maps.hpp"

using miner::world::Box;
using miner::world::Map;
using miner::world::VoxelLayer;
using miner::world::VoxelState;
using Catch::Matchers::Contains;
using V = Eigen::Vector3d;

namespace {

std::string slurp(const std::string& path) { return miner::read_file_bytes(path); }

/// A tree OctoMap builds itself: free space over a 40 x 30 x 20 voxel block at 0.1 m with a
/// hole of unknown, occupied 8^3 blocks aligned to the tree (pruned to one leaf each) and
/// scattered single occupied voxels, drawn from `seed`.
template <typename Tree>
void fill_tree(Tree& tree, std::uint64_t seed) {
  miner::Rng rng(seed);
  for (int z = -8; z < 12; ++z)
    for (int y = -10; y < 20; ++y)
      for (int x = -16; x < 24; ++x) {
        if (x > 10 && y > 10 && z > 4) continue;  // never observed: unknown
        tree.updateNode(tree.coordToKey(octomap::point3d(static_cast<float>(x + 0.5) * 0.1f,
                                                         static_cast<float>(y + 0.5) * 0.1f,
                                                         static_cast<float>(z + 0.5) * 0.1f)),
                        false);
      }
  for (int b = 0; b < 3; ++b) {
    const int bx = 8 * static_cast<int>(rng.uniform_index(4)) - 16, by = 8 * static_cast<int>(rng.uniform_index(3)) - 8;
    for (int z = 0; z < 8; ++z)
      for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x)
          tree.updateNode(tree.coordToKey(octomap::point3d(static_cast<float>(bx + x + 0.5) * 0.1f,
                                                           static_cast<float>(by + y + 0.5) * 0.1f,
                                                           static_cast<float>(z + 0.5) * 0.1f)),
                          true);
  }
  for (int i = 0; i < 60; ++i) {
    const double x = rng.uniform(-1.6, 2.4), y = rng.uniform(-1.0, 2.0), z = rng.uniform(-0.8, 1.2);
    tree.updateNode(tree.coordToKey(octomap::point3d(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z))),
                    true);
  }
  tree.updateInnerOccupancy();
}

/// Every voxel of a box around the layer has the state OctoMap's own search gives it, and the
/// occupied volume is the occupied leaves' volume.
template <typename Tree>
void check_same_voxels(const Tree& tree, const VoxelLayer& layer) {
  const Eigen::Vector3i o = layer.origin_cells();
  std::size_t mismatches = 0;
  for (int z = -2; z < layer.dims().z() + 2; ++z)
    for (int y = -2; y < layer.dims().y() + 2; ++y)
      for (int x = -2; x < layer.dims().x() + 2; ++x) {
        const octomap::OcTreeKey key(static_cast<octomap::key_type>(o.x() + x + miner::world::kOctreeKeyOffset),
                                     static_cast<octomap::key_type>(o.y() + y + miner::world::kOctreeKeyOffset),
                                     static_cast<octomap::key_type>(o.z() + z + miner::world::kOctreeKeyOffset));
        const auto* node = tree.search(key);
        const VoxelState expected =
            node == nullptr ? VoxelState::kUnknown : (tree.isNodeOccupied(node) ? VoxelState::kOccupied : VoxelState::kFree);
        const bool inside = x >= 0 && y >= 0 && z >= 0 && x < layer.dims().x() && y < layer.dims().y() &&
                            z < layer.dims().z();
        const VoxelState got = inside ? layer.state(layer.index(x, y, z)) : VoxelState::kUnknown;
        mismatches += got != expected;
      }
  CHECK(mismatches == 0);
  double occupied_volume = 0.0;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it)
    if (tree.isNodeOccupied(*it)) occupied_volume += std::pow(it.getSize(), 3);
  const double r = layer.resolution();
  CHECK(static_cast<double>(layer.count(VoxelState::kOccupied)) * r * r * r == Approx(occupied_volume).epsilon(1e-9));
  // Bounds: the known leaves' extent, exact multiples of the resolution.
  double x0, y0, z0, x1, y1, z1;
  const_cast<Tree&>(tree).getMetricMin(x0, y0, z0);
  const_cast<Tree&>(tree).getMetricMax(x1, y1, z1);
  CHECK(layer.bounds().min.isApprox(V(x0, y0, z0), 1e-6));
  CHECK(layer.bounds().max.isApprox(V(x1, y1, z1), 1e-6));
}

}  // namespace

TEST_CASE("OctoMap binary trees load with their exact leaves, free, occupied and unknown", "[REQ-WORLD-003][REQ-WORLD-012]") {
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    octomap::OcTree tree(0.1);
    fill_tree(tree, seed);
    const std::string path = miner::world::test::temp_path("octomap_" + std::to_string(seed) + ".bt");
    REQUIRE(tree.writeBinary(path));
    octomap::OcTree ml(0.1);  // writeBinary stores the maximum-likelihood tree: compare with that
    REQUIRE(ml.readBinary(path));
    const Map map = Map::load(path);
    REQUIRE(map.voxels() != nullptr);
    CHECK(map.resolution() == 0.1);
    CHECK(map.obstacles().empty());
    check_same_voxels(ml, map.voxels()->layer());
    CHECK(map.voxels()->layer().count(VoxelState::kUnknown) > 0);
    // Same bytes back: MINER's writer emits what OctoMap writes for these voxels.
    const std::string bytes = slurp(path);
    CHECK(miner::world::octree_bt_bytes(map.voxels()->layer()) == bytes);
    // And a round trip through MINER is stable to the byte.
    const std::string again = miner::world::test::temp_path("octomap_again.bt");
    map.save(again);
    CHECK(slurp(again) == bytes);
    CHECK(miner::world::octree_bt_bytes(Map::load(again).voxels()->layer()) == bytes);
  }
}

TEST_CASE("OctoMap full trees (.ot) load by their log-odds, OcTree and ColorOcTree", "[REQ-WORLD-003][REQ-WORLD-012]") {
  octomap::OcTree tree(0.1);
  fill_tree(tree, 7);
  // A leaf at log-odds exactly 0 (probability 0.5) is occupied, as OctoMap's isNodeOccupied
  // (>= its 0.5 threshold) says (held-out audit 7, h7-world-06 read it as free).
  const octomap::point3d even(0.05f, 0.05f, 0.05f);
  tree.setNodeValue(even, 0.0f);
  REQUIRE(tree.search(even) != nullptr);
  REQUIRE(tree.search(even)->getLogOdds() == 0.0f);
  REQUIRE(tree.isNodeOccupied(tree.search(even)));
  const std::string path = miner::world::test::temp_path("octomap.ot");
  REQUIRE(tree.write(path));
  const Map loaded = Map::load(path);
  check_same_voxels(tree, loaded.voxels()->layer());
  CHECK(loaded.point_collision(V(even.x(), even.y(), even.z())));

  octomap::ColorOcTree color(0.1);
  fill_tree(color, 8);
  const std::string cpath = miner::world::test::temp_path("octomap_color.ot");
  REQUIRE(color.write(cpath));
  check_same_voxels(color, Map::load(cpath).voxels()->layer());
}

TEST_CASE("A box map survives a round trip through an OctoMap .bt file", "[REQ-WORLD-003]") {
  const Map map(Box{{0, 0, 0}, {4, 4, 2}}, 0.5, {Box{{1, 1, 0}, {2, 3, 1.5}}, Box{{3, 0, 0}, {3.5, 0.5, 0.5}}});
  const std::string path = miner::world::test::temp_path("roundtrip.bt");
  map.save(path);
  const Map back = Map::load(path);
  CHECK(back.resolution() == 0.5);
  for (const Box& b : map.obstacles()) {
    for (double x = b.min.x() + 0.1; x < b.max.x(); x += 0.2)
      for (double y = b.min.y() + 0.1; y < b.max.y(); y += 0.2)
        for (double z = b.min.z() + 0.1; z < b.max.z(); z += 0.2) {
          INFO(miner::format_point(V(x, y, z)));
          CHECK(back.point_collision(V(x, y, z)));
        }
  }
  // Free space is known free (not unknown), so the bounds and the free cells survive.
  CHECK_FALSE(back.point_collision(V(0.25, 3.75, 1.75)));
  CHECK(back.voxels()->layer().count(VoxelState::kUnknown) == 0);
  CHECK(back.bounds().min == map.bounds().min);
  CHECK(back.bounds().max == map.bounds().max);
  // No growth: the occupied voxels are those the obstacles cover (1x2x1.5 m + 0.5^3 m).
  CHECK(static_cast<double>(back.voxels()->layer().count(VoxelState::kOccupied)) * 0.125 == Approx(3.0 + 0.125));
  const std::string again = miner::world::test::temp_path("roundtrip2.bt");
  back.save(again);
  CHECK(slurp(again) == slurp(path));
}

TEST_CASE("A tiny .bt whose two leaves lie far apart is refused by its grid size before any work",
          "[REQ-WORLD-014][REQ-WORLD-002]") {
  // Issue 20, fifth campaign: 180 bytes, two leaves 639 voxels apart, 2.6e8 voxels: under the old
  // 2^28 bound, planning on it took 4.9 GB and over a minute.
  octomap::OcTree tree(0.1);
  tree.updateNode(octomap::point3d(0.05f, 0.05f, 0.05f), true);
  tree.updateNode(octomap::point3d(63.95f, 63.95f, 63.95f), true);
  const std::string path = miner::world::test::temp_path("far-leaves.bt");
  tree.writeBinary(path);
  CHECK_THROWS_WITH(Map::load(path), Contains("far-leaves.bt: the known leaves span 640 x 640 x 640 voxels, more than the 6.71089e+07"));
}

TEST_CASE("A .bt whose voxels lie far from the origin is refused naming the file", "[REQ-WORLD-014][REQ-WORLD-002]") {
  // Issue 20, sixth campaign U2: "bounds.min: ... lies farther than 1e+06 m" named no file.
  octomap::OcTree tree(50.0);
  tree.updateNode(octomap::point3d(-1500000.0f, 25.0f, 25.0f), true);
  const std::string path = miner::world::test::temp_path("far-origin.bt");
  tree.writeBinary(path);
  CHECK_THROWS_WITH(Map::load(path), Contains("far-origin.bt: the map its voxels span: bounds.min: (") &&
                                         Contains("lies farther than 1e+06 m from the origin"));
}

TEST_CASE("A map whose bounds are off its resolution's lattice is not written as a larger .bt", "[REQ-WORLD-003]") {
  // 4 m at 0.3 m is 13.33 cells: the .bt would cover 4.2 m (issue 20, fourth campaign).
  const std::string path = miner::world::test::temp_path("offlattice.bt");
  std::filesystem::remove(path);
  CHECK_THROWS_WITH(Map(Box{{0, 0, 0}, {4, 4, 3}}, 0.3, {}).save(path),
                    Contains("bounds: (0, 0, 0) - (4, 4, 3) are not whole multiples of the resolution 0.3 m along x") &&
                        Contains("so " + path + " would cover more than the map"));
  CHECK_FALSE(std::filesystem::exists(path));
  CHECK_THROWS_WITH(Map(Box{{0.1, 0, 0}, {4.1, 4, 3}}, 0.5, {}).save(path), Contains("along x (0.1 m is 0.2 cells)"));
  CHECK_NOTHROW(Map(Box{{-0.6, 0, 0}, {3, 4.2, 3}}, 0.3, {}).save(path));  // on the lattice: -2, 10, 14 cells
  CHECK(Map::load(path).bounds().max.y() == Approx(4.2));
}

namespace {

/// A valid .bt file's header and data, for the malformed-file cases.
std::pair<std::string, std::string> valid_bt() {
  octomap::OcTree tree(0.1);
  fill_tree(tree, 4);
  std::ostringstream os;
  tree.writeBinary(os);
  const std::string bytes = os.str();
  const std::size_t data = bytes.find("data\n") + 5;
  return {bytes.substr(0, data), bytes.substr(data)};
}

std::string header(std::size_t size, const std::string& res = "0.1", const std::string& id = "OcTree") {
  return "# Octomap OcTree binary file\nid " + id + "\nsize " + std::to_string(size) + "\nres " + res + "\ndata\n";
}

void refuses(const std::string& bytes, const std::string& message) {
  INFO(message);
  const std::string path = miner::world::test::temp_path("bad.bt");
  std::ofstream(path, std::ios::binary) << bytes;
  CHECK_THROWS_WITH(Map::load(path), Contains("bad.bt: ") && Contains(message));
}

}  // namespace

TEST_CASE("Malformed OctoMap files are refused naming the fault, never crash", "[REQ-WORLD-014][REQ-WORLD-003]") {
  CHECK_THROWS_WITH(Map::load(miner::world::test::temp_path("missing.bt")), Contains("missing.bt: cannot open"));
  refuses("this is not an octree\n", "not an OctoMap file");
  refuses("", "empty file");
  refuses("# Octomap OcTree binary file\nid OcTree\nsize 3\n", "header ends before its \"data\" line");
  refuses("# Octomap OcTree binary file\nid OcTree\nres 0.1\ndata\n", "header lacks size");
  refuses(header(1, "-0.1"), "header res \"-0.1\"");
  refuses(header(1, "nan"), "header res \"nan\"");
  refuses(header(1, "0.1", "ColorOcTree"), "binary tree id \"ColorOcTree\"");
  refuses("# Octomap OcTree binary file\nid OcTree\nsize 1\nres 0.1\ncolour red\ndata\n", "unknown header key \"colour\"");
  refuses(header(0), "empty (size 0)");
  // Issue 20: resolutions outside a map's range (1e-300 overflowed the grid's inflation, 1e300
  // made planning hang) and a header key given twice (the last one silently won).
  refuses(header(1, "1e-300"), "header res 1e-300 m is outside the resolutions a map may have [0.001, 100] m");
  refuses(header(1, "1e300"), "header res 1e300 m is outside");
  refuses(header(1, "0x1p-1"), "header res \"0x1p-1\" is not a positive resolution");  // strtod reads hex
  refuses("# Octomap OcTree binary file\nid OcTree\nsize 1\nres 0.5\nres 5\ndata\n", "header key \"res\" is given twice");
  const auto [head, data] = valid_bt();
  refuses(head + data.substr(0, data.size() / 2), "data ends early");
  refuses(head + data + std::string("\x01\x02", 2), "2 bytes follow the tree's last node");
  // Header size off by one either way.
  const std::size_t nodes = std::stoul(head.substr(head.find("size ") + 5));
  refuses(header(nodes + 1) + data, "data holds " + std::to_string(nodes) + " nodes, the header announces");
  refuses(header(nodes - 1) + data, "the header announces " + std::to_string(nodes - 1));
  // Inner nodes all the way down: the 16th level may not have children (no unbounded descent).
  refuses(header(1000) + std::string(40, '\xff'), "a node at depth 16 claims children");
  // A valid header followed by random bytes (the input that overflowed OctoMap's reader).
  {
    miner::Rng rng(5);
    std::string noise(1 << 20, '\0');
    for (char& c : noise) c = static_cast<char>(rng.uniform_index(256));
    const std::string path = miner::world::test::temp_path("noise.bt");
    std::ofstream(path, std::ios::binary) << header(1u << 20) << noise;
    CHECK_THROWS_AS(Map::load(path), miner::Error);
  }
  // Two leaves at opposite corners of OctoMap's key space: refused before allocating the grid.
  {
    // Root: children 0 and 7 inner; chains through child 0 (resp. 7) down to a depth-16 leaf.
    std::string lo, hi;
    for (int d = 1; d <= 14; ++d) {
      lo += std::string("\x03\x00", 2);
      hi += std::string("\x00\xc0", 2);
    }
    lo += std::string("\x02\x00", 2);
    hi += std::string("\x00\x80", 2);
    refuses(header(33) + std::string("\x03\xc0", 2) + lo + hi, "voxels, more than the");
  }
  // Random corruption of a valid file: it loads or it is refused, nothing else.
  miner::Rng rng(9);
  const std::string path = miner::world::test::temp_path("mutated.bt");
  int refused = 0;
  for (int trial = 0; trial < 400; ++trial) {
    std::string bytes = head + data;
    const int flips = 1 + static_cast<int>(rng.uniform_index(4));
    for (int f = 0; f < flips; ++f) bytes[rng.uniform_index(bytes.size())] = static_cast<char>(rng.uniform_index(256));
    if (rng.uniform01() < 0.3) bytes.resize(rng.uniform_index(bytes.size()));
    std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
    try {
      (void)Map::load(path);
    } catch (const miner::Error& e) {
      ++refused;
      CHECK_THAT(e.what(), Contains("mutated.bt"));
    }
  }
  CHECK(refused > 0);
}

TEST_CASE("A full tree (.ot) of another tree type or with a non-finite log-odds is refused naming it and a map outside OctoMap's keys is not written",
          "[REQ-WORLD-014][REQ-WORLD-003]") {
  octomap::OcTree tree(0.1);
  fill_tree(tree, 3);
  const std::string path = miner::world::test::temp_path("full.ot");
  REQUIRE(tree.write(path));
  const std::string good = slurp(path);
  REQUIRE_NOTHROW(Map::load(path));
  const std::size_t data = good.find("data\n") + 5;
  REQUIRE(data > 5);
  const auto load_bytes = [&](const std::string& bytes, const std::string& name) {
    const std::string p = miner::world::test::temp_path(name);
    std::ofstream(p, std::ios::binary | std::ios::trunc) << bytes;
    return Map::load(p);
  };
  // OctoMap's other full-tree types (stamped, counting) carry other node layouts.
  for (const char* id : {"OcTreeStamped", "CountingOcTree"}) {
    std::string other = good;
    other.replace(other.find("id OcTree\n"), 10, std::string("id ") + id + "\n");
    CHECK_THROWS_WITH(load_bytes(other, "other.ot"), Contains("other.ot") && Contains(std::string("tree id \"") + id + "\" is not one MINER reads"));
  }
  // The root's log-odds (the first 4 bytes of the data) NaN, then a leaf's +inf.
  std::string nan_root = good;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(&nan_root[data], &nan, sizeof nan);
  CHECK_THROWS_WITH(load_bytes(nan_root, "nan.ot"), Contains("nan.ot") && Contains("node 1 has a non-finite log-odds value"));
  std::string inf_node = good;
  const float inf = std::numeric_limits<float>::infinity();
  std::memcpy(&inf_node[data + 5], &inf, sizeof inf);  // the root's first child: 4 bytes + its child mask further on
  CHECK_THROWS_WITH(load_bytes(inf_node, "inf.ot"), Contains("inf.ot") && Contains("has a non-finite log-odds value"));
  // Writing: OctoMap keys reach 32768 voxels either side of the origin.
  const VoxelLayer far(Eigen::Vector3i(-40000, 0, 0), 0.1, Eigen::Vector3i(2, 2, 2), std::vector<std::uint8_t>(8, 0));
  const std::string out = miner::world::test::temp_path("far.bt");
  CHECK_THROWS_WITH(miner::world::write_octree_bt(far, out), Contains("far.bt: the map lies outside OctoMap's key range"));
  CHECK_FALSE(std::filesystem::exists(out));
  const VoxelLayer unknown(Eigen::Vector3i::Zero(), 0.1, Eigen::Vector3i(2, 2, 2),
                           std::vector<std::uint8_t>(8, static_cast<std::uint8_t>(VoxelState::kUnknown)));
  CHECK_THROWS_WITH(miner::world::write_octree_bt(unknown, out), Contains("the map has no known voxel to write"));
}
