#include <catch2/catch.hpp>

#include <deque>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <set>
#include <sstream>

#include <unistd.h>

#include "miner/core/error.hpp"
#include "miner/core/json_io.hpp"
#include "miner/core/progress.hpp"
#include "miner/core/sha256.hpp"
#include "miner/heuristic/dataset.hpp"
#include "miner/heuristic/grid.hpp"
#include "miner/plan/heuristic_region.hpp"
#include "miner/world/astar.hpp"
#include "miner/world/map_generator.hpp"
#include "miner/world/voxel_grid.hpp"

using Catch::Matchers::Contains;
using Catch::Matchers::EndsWith;
namespace heuristic = miner::heuristic;

namespace {

std::string temp_dir() {
  const auto p = std::filesystem::temp_directory_path() / ("miner_heuristic_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(p);
  return p.string();
}

heuristic::DatasetOptions small_options() {
  heuristic::DatasetOptions o;
  o.preset = "indoor";
  o.count = 4;  // 3 train (two shards of 2 and 1), 1 val, 1 test: every split and a partial shard
  o.test_count = 1;
  o.val_fraction = 0.25;
  o.seed = 5;
  o.shard_size = 2;
  return o;
}

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

TEST_CASE("Environment cells are free, partial where a grown obstacle meets them, solid where grown obstacles cover them",
          "[REQ-HEUR-002]") {
  using miner::world::Box;
  const miner::world::Map map(Box{{0, 0, 0}, {8, 8, 4}}, 0.5,
                              {Box{{1.0, 1.0, 0.0}, {2.0, 3.0, 1.0}}, Box{{5.3, 5.9, 2.2}, {5.4, 6.0, 2.3}}});
  const Eigen::Vector3i dims(8, 8, 4);  // 1 m cells
  // r = 0 puts the first box's faces on cell edges: a cell whose closed box only touches it is
  // met, on its low face as on its high one (held-out audit 6, h6-heuristic-05 missed the
  // touch on the low face).
  for (const double r : {0.2, 0.0}) {
  INFO("robot radius " << r);
  const auto e = heuristic::encode_environment(map, dims, r);
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 8; ++j)
      for (int i = 0; i < 8; ++i) {
        const Box cell{Eigen::Vector3d(i, j, k), Eigen::Vector3d(i + 1, j + 1, k + 1)};
        bool hit = false;
        for (const Box& o : map.obstacles()) {
          const Box g = o.inflated(r);
          hit = hit || ((cell.min.array() <= g.max.array()).all() && (g.min.array() <= cell.max.array()).all());
        }
        // Covered: every point of a fine lattice over the closed cell is in a grown box.
        bool covered = hit;
        for (int a = 0; a <= 8 && covered; ++a)
          for (int b = 0; b <= 8 && covered; ++b)
            for (int c = 0; c <= 8 && covered; ++c) {
              const Eigen::Vector3d p = cell.min + Eigen::Vector3d(a, b, c) / 8.0;
              bool in = false;
              for (const Box& o : map.obstacles()) {
                const Box g = o.inflated(r);
                in = in || ((p.array() >= g.min.array()).all() && (p.array() <= g.max.array()).all());
              }
              covered = in;
            }
        CHECK(e[(static_cast<std::size_t>(k) * 8 + j) * 8 + i] == (covered ? 2 : hit ? 1 : 0));
      }
  CHECK(e[(0 * 8 + 1) * 8 + 1] == heuristic::kSolid);  // [1,2]x[1,2]x[0,1] inside [0.8,2.2]x[0.8,3.2]x[-0.2,1.2]
  if (r == 0.0) {
    CHECK(e[(0 * 8 + 1) * 8 + 2] == heuristic::kPartial);  // [2,3]x[1,2]x[0,1] touches x = 2 on its low face
    CHECK(e[(0 * 8 + 1) * 8 + 0] == heuristic::kPartial);  // [0,1]x[1,2]x[0,1] touches x = 1 on its high face
  }
  }
}

TEST_CASE("A cell covered only by the union of two boxes is covered: a gap of any width is found", "[REQ-HEUR-002][REQ-HEUR-012]") {
  using miner::world::Box;
  const Box cell{{0, 0, 0}, {1, 1, 1}};
  CHECK(heuristic::box_covered(cell, {Box{{-1, -1, -1}, {0.4, 2, 2}}, Box{{0.4, -1, -1}, {2, 2, 2}}}));
  CHECK_FALSE(heuristic::box_covered(cell, {Box{{-1, -1, -1}, {0.4, 2, 2}}, Box{{0.41, -1, -1}, {2, 2, 2}}}));
  CHECK_FALSE(heuristic::box_covered(cell, {Box{{-1, -1, -1}, {2, 2, 0.999}}}));
  CHECK_FALSE(heuristic::box_covered(cell, {}));
  // Through the encoder, whose volume bound skips the cut when the boxes cannot fill a cell
  // (issue 16): two halves fill cell (0, 0, 0); with a gap, or too little volume, they do not.
  const auto encode = [](std::vector<Box> boxes) {
    const miner::world::Map map(Box{{0, 0, 0}, {4, 4, 4}}, 0.5, std::move(boxes));
    return heuristic::encode_environment(map, Eigen::Vector3i(4, 4, 4), 0.0)[0];
  };
  CHECK(encode({Box{{0, 0, 0}, {0.4, 1, 1}}, Box{{0.4, 0, 0}, {1, 1, 1}}}) == heuristic::kSolid);
  CHECK(encode({Box{{0, 0, 0}, {0.4, 1, 1}}, Box{{0.41, 0, 0}, {1, 1, 1}}}) == heuristic::kPartial);
  CHECK(encode({Box{{0, 0, 0}, {0.4, 1, 1}}, Box{{0.4, 0, 0}, {1, 1, 0.5}}, Box{{0.4, 0, 0.5}, {1, 1, 1}}}) ==
        heuristic::kSolid);
}

TEST_CASE("Boxes encode in work bounded by the cells they meet without holding, the same E", "[REQ-HEUR-012]") {
  using miner::world::Box;
  namespace h = miner::heuristic;
  const Eigen::Vector3i dims(32, 32, 32);
  // 500 boxes spanning the map but its top metre (issue 20: 20 000 such boxes took 29 s, each
  // cell of the grid listed against every box; the hostile size is the campaigns', kept small
  // here for the sanitizer build, where 5 000 took 380 s and 1 500 95 s): E is the one box's E,
  // cell for cell; so are boxes that differ by less than a cell, whose tops cut the top layer apart.
  const Box bounds{{0, 0, 0}, {400, 400, 100}};
  const miner::world::Map one(bounds, 1.0, {Box{{0, 0, 0}, {400, 400, 99}}});
  const std::vector<std::uint8_t> e_one = h::encode_environment(one, dims, 0.3);
  constexpr int kBoxes = 500;
  constexpr double kStep = 9e-4;  // the tops spread over 0.45 m, inside the top layer's cells
  std::vector<Box> copies(kBoxes, Box{{0, 0, 0}, {400, 400, 99}}), staggered;
  for (int i = 0; i < kBoxes; ++i) staggered.push_back(Box{{0, 0, 0}, {400, 400, 98.0 + kStep * i}});
  const miner::world::Map many(bounds, 1.0, copies), stair(bounds, 1.0, staggered);
  CHECK(h::encode_environment(many, dims, 0.3) == e_one);
  CHECK(h::encode_environment_passability(many, dims, 0.3).passability ==
        h::encode_environment_passability(one, dims, 0.3).passability);
  const miner::world::Map top(bounds, 1.0, {Box{{0, 0, 0}, {400, 400, 98.0 + kStep * (kBoxes - 1)}}});
  CHECK(h::encode_environment(stair, dims, 0.3) == h::encode_environment(top, dims, 0.3));
  // The layers: solid below the top layer's cells, which the boxes' tops cut (partial).
  CHECK(e_one[h::cell_index(dims, 5, 5, 0)] == h::kSolid);
  CHECK(e_one[h::cell_index(dims, 5, 5, 30)] == h::kSolid);
  CHECK(e_one[h::cell_index(dims, 5, 5, 31)] == h::kPartial);

  // Past kMaxEncodeShellCells cells met without being held, the map is refused before the work:
  // 400 boxes each meeting every cell of a 256^3 grid and holding all but its outer layer
  // (~390 000 cells each).
  const miner::world::Map fine(Box{{0, 0, 0}, {10, 10, 10}}, 0.5,
                               std::vector<Box>(400, Box{{0.01, 0.01, 0.01}, {9.99, 9.99, 9.99}}));
  CHECK_THROWS_WITH(h::encode_environment(fine, Eigen::Vector3i(256, 256, 256), 0.0),
                    Catch::Contains("400 obstacles") && Catch::Contains("more than the bound 134217728"));
}

TEST_CASE("The exact cover test is bounded per cell and per encoding: past its budget it answers unproven (partial)",
          "[REQ-HEUR-012]") {
  using miner::world::Box;
  const Box cell{{0, 0, 0}, {1, 1, 1}};
  // One box holds the cell; n small boxes with their own faces inside it cut it into
  // (2n + 1)^3 sub-boxes, each tested against the n + 1 boxes.
  const auto boxes = [](int n) {
    std::vector<Box> b{Box{{-1, -1, -1}, {2, 2, 2}}};
    for (int i = 0; i < n; ++i)  // faces all distinct: lows in [0.1, 0.3), highs in [0.6, 0.8)
      b.push_back(Box{Eigen::Vector3d::Constant(0.1 + 0.005 * i), Eigen::Vector3d::Constant(0.6 + 0.005 * i)});
    return b;
  };
  CHECK(miner::heuristic::box_covered(cell, boxes(10)));        // 21^3 x 11: proven
  CHECK_FALSE(miner::heuristic::box_covered(cell, boxes(39)));  // 79^3 x 40 > 2^24: unproven
  // An encoding's budget over all its cells: the tests are taken from it while it lasts
  // (21^3 x 11 = 101 871 per call here), then cells stay unproven.
  std::uint64_t budget = 250000;
  CHECK(miner::heuristic::box_covered(cell, boxes(10), &budget));
  CHECK(budget == 250000 - 101871);
  CHECK(miner::heuristic::box_covered(cell, boxes(10), &budget));
  CHECK_FALSE(miner::heuristic::box_covered(cell, boxes(10), &budget));
  CHECK(budget == 250000 - 2 * 101871);
}

TEST_CASE("Regions connect through faces, edges and corners only", "[REQ-HEUR-004]") {
  const Eigen::Vector3i d(4, 4, 4);
  std::vector<std::uint8_t> m(64, 0);
  auto set = [&](int i, int j, int k) { m[heuristic::cell_index(d, i, j, k)] = 1; };
  set(0, 0, 0);
  set(1, 1, 1);  // corner neighbour
  set(3, 3, 3);  // two cells away from (1,1,1)
  CHECK(heuristic::connects(m, d, {0, 0, 0}, {1, 1, 1}));
  CHECK_FALSE(heuristic::connects(m, d, {0, 0, 0}, {3, 3, 3}));
  CHECK_FALSE(heuristic::connects(m, d, {0, 0, 0}, {2, 2, 2}));  // the end cell is not in the region
  set(2, 2, 2);
  CHECK(heuristic::connects(m, d, {0, 0, 0}, {3, 3, 3}));
  const auto labels = heuristic::label_components(m, d);
  CHECK(labels[heuristic::cell_index(d, 3, 3, 3)] == 1);
  CHECK(labels[heuristic::cell_index(d, 0, 1, 0)] == 0);
  std::vector<std::uint8_t> env(64, heuristic::kFree);
  env[heuristic::cell_index(d, 2, 2, 2)] = heuristic::kSolid;
  env[heuristic::cell_index(d, 0, 1, 0)] = heuristic::kSolid;  // outside the region
  CHECK(heuristic::solid_cells_in(m, env) == 1);
}

TEST_CASE("A sample keeps its start and goal min_separation of the diagonal apart or is refused", "[REQ-HEUR-002][REQ-HEUR-003]") {
  // Fourteenth campaign L4: asked 0.9 and 0.99 of the diagonal, sample 0 of sim came back 0.842
  // apart (the map's own query, taken when the draws found none).
  auto o = small_options();
  o.preset = "sim";
  for (const double separation : {0.0, 0.5, 0.8, 0.9, 0.99}) {
    o.min_separation = separation;
    INFO("min_separation " << separation);
    try {
      const heuristic::Sample s = heuristic::make_sample(o, 0);
      CHECK((s.goal - s.start).norm() >= separation * (s.bounds.max - s.bounds.min).norm());
    } catch (const miner::Error& e) {
      CHECK_THAT(e.what(), Contains("sample 0: no free, connected start and goal") && Contains("lower min_separation"));
      CHECK(separation > 0.8);  // the draws and the map's own query (0.842) meet 0.8
    }
  }
}

TEST_CASE("A sample's state marks 3x3x3 cubes at start and goal and its target is a connected region between them",
          "[REQ-HEUR-002]") {
  const auto o = small_options();
  const heuristic::Sample s = heuristic::make_sample(o, 0);
  const Eigen::Vector3i d = o.dims;
  const std::size_t n = static_cast<std::size_t>(d.prod());
  REQUIRE(s.environment.size() == n);
  const auto count = [](const std::vector<std::uint8_t>& v) { return std::count(v.begin(), v.end(), 1); };
  CHECK(count(s.state) <= 54);
  CHECK(count(s.state) >= 27);  // two cubes, overlapping or clipped at the border at most
  CHECK((s.goal - s.start).norm() >= o.min_separation * Eigen::Vector3d(10, 10, 5).norm());
  auto cell = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector3d c = Eigen::Vector3d(10, 10, 5).cwiseQuotient(d.cast<double>());
    Eigen::Vector3i i = p.cwiseQuotient(c).array().floor().cast<int>();
    return (static_cast<std::size_t>(i.z()) * d.y() + i.y()) * d.x() + i.x();
  };
  REQUIRE(s.target[cell(s.start)] == 1);
  REQUIRE(s.target[cell(s.goal)] == 1);
  // 26-connected flood fill inside T from the start's cell reaches the goal's cell.
  std::vector<std::uint8_t> seen(n, 0);
  std::deque<std::size_t> queue{cell(s.start)};
  seen[queue.front()] = 1;
  while (!queue.empty()) {
    const std::size_t c = queue.front();
    queue.pop_front();
    const int x = static_cast<int>(c % d.x()), y = static_cast<int>((c / d.x()) % d.y()), z = static_cast<int>(c / (d.x() * d.y()));
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int a = x + dx, b = y + dy, e = z + dz;
          if (a < 0 || b < 0 || e < 0 || a >= d.x() || b >= d.y() || e >= d.z()) continue;
          const std::size_t m = (static_cast<std::size_t>(e) * d.y() + b) * d.x() + a;
          if (s.target[m] && !seen[m]) {
            seen[m] = 1;
            queue.push_back(m);
          }
        }
  }
  CHECK(seen[cell(s.goal)] == 1);
  CHECK(heuristic::solid_cells_in(s.target, s.environment) == 0);
  CHECK(s.astar_cost >= (s.goal - s.start).norm());
}

TEST_CASE("T is the A* path's cells and the free cells of their dilation, never a partial cell off the path",
          "[REQ-HEUR-002]") {
  std::size_t partial_dropped_all = 0;  // the rule is exercised: some tube cells are partial
  for (const char* preset : {"indoor", "cluttered", "rooms"}) {
    INFO(preset);
    auto o = small_options();
    o.preset = preset;
    const heuristic::Sample s = heuristic::make_sample(o, 1);
    // The same A* path again, from the sample's map and query.
    const miner::world::GeneratorPreset p = miner::world::generator_preset(preset);
    const miner::world::Map map = miner::world::generate_map(p, s.map_seed);
    const miner::world::VoxelGrid grid(map, p.robot_radius);
    const miner::world::GridPath path = miner::world::astar(map, grid, s.start, s.goal);
    REQUIRE(path.cost == Approx(s.astar_cost));
    const auto own = miner::plan::HeuristicRegion::from_path(map.bounds(), o.dims, path.points, 0, "own");
    const auto tube = miner::plan::HeuristicRegion::from_path(map.bounds(), o.dims, path.points, 1, "tube");
    std::vector<std::uint8_t> on(s.target.size(), 0), in_tube(s.target.size(), 0);
    for (std::size_t c : own.cells()) on[c] = 1;
    for (std::size_t c : tube.cells()) in_tube[c] = 1;
    std::size_t partial_dropped = 0;
    for (std::size_t c = 0; c < s.target.size(); ++c) {
      const bool want = on[c] || (in_tube[c] && s.environment[c] == heuristic::kFree);
      REQUIRE(static_cast<bool>(s.target[c]) == want);
      partial_dropped += in_tube[c] && !on[c] && s.environment[c] == heuristic::kPartial;
    }
    CHECK(std::count(on.begin(), on.end(), 1) > 0);
    partial_dropped_all += partial_dropped;
  }
  CHECK(partial_dropped_all > 0);
}

TEST_CASE("The dataset has its splits, unseen test seeds and the same bytes for a seed", "[REQ-HEUR-001]") {
  const auto o = small_options();
  const std::string a = temp_dir() + "/a", b = temp_dir() + "/b";
  const miner::Json doc = heuristic::write_dataset(o, a, nullptr);
  auto parallel = o;
  parallel.jobs = 3;
  heuristic::write_dataset(parallel, b, nullptr);
  CHECK(doc["splits"]["train"]["count"] == 3);
  CHECK(doc["splits"]["val"]["count"] == 1);
  CHECK(doc["splits"]["test"]["count"] == 1);
  CHECK(doc["splits"]["train"]["shards"].size() == 2);  // shard size 2
  for (const char* f : {"dataset.json", "train-00000.bin", "train-00001.bin", "val-00000.bin", "test-00000.bin",
                        "train-index.json", "test-index.json"})
    CHECK(read_bytes(a + "/" + f) == read_bytes(b + "/" + f));
  const auto train = heuristic::read_split(a, "train"), val = heuristic::read_split(a, "val"),
             test = heuristic::read_split(a, "test");
  REQUIRE(train.size() == 3);
  REQUIRE(val.size() == 1);
  REQUIRE(test.size() == 1);
  std::set<std::uint64_t> seen;
  for (const auto* split : {&train, &val})
    for (const auto& s : *split) seen.insert(s.map_seed);
  for (const auto& s : test) CHECK(seen.count(s.map_seed) == 0);
  // What is read back is what make_sample produces.
  const heuristic::Sample again = heuristic::make_sample(o, 3);  // k = 3: the val sample
  CHECK(val[0].target == again.target);
  CHECK(val[0].environment == again.environment);
  CHECK(val[0].start == again.start);
  // Written again over itself it is replaced; a user's file of the dataset's extensions kept in
  // it makes the write refuse, naming it, and stays (seventeenth campaign F31: notes.json and
  // readme.bin were deleted with the folder).
  heuristic::write_dataset(o, a, nullptr);
  std::ofstream(a + "/notes.json") << "{\"x\": 1}";
  CHECK_THROWS_WITH(heuristic::write_dataset(o, a, nullptr), Contains("\"notes.json\", which the earlier output did not write"));
  CHECK(read_bytes(a + "/notes.json") == "{\"x\": 1}");
  std::filesystem::remove(a + "/notes.json");
  const auto own = heuristic::dataset_folder_marker().own_name;
  for (const char* name : {"dataset.json", "train-00000.bin", "val-12345.bin", "test-index.json", "train-123456.bin"})
    CHECK(own(name));
  for (const char* name : {"notes.json", "readme.bin", "train-1.bin", "train-00000.bin.bak", "extra-index.json"})
    CHECK_FALSE(own(name));
  // A truncated shard is refused naming the file and the sizes.
  std::filesystem::resize_file(a + "/test-00000.bin", 100);
  CHECK_THROWS_WITH(heuristic::read_split(a, "test"), Contains("test-00000.bin") && Contains("expected"));
}

TEST_CASE("A part that would hold no shard file is refused before any sample is drawn", "[REQ-REPORT-006]") {
  // Issue 20, sixth campaign U12: --shard 5/6 of a dataset with 2 shard files per split wrote an
  // empty part and said "4 train, 0 val, 2 test samples".
  auto o = small_options();
  o.dims = Eigen::Vector3i(8, 8, 4);
  o.shard_count = 3;  // the training split has 2 files of 2 samples: part 2 gets none
  o.shard_index = 2;
  const std::string out = temp_dir() + "/empty-part";
  std::filesystem::remove_all(out);
  CHECK_THROWS_WITH(heuristic::write_dataset(o, out, nullptr),
                    Contains("--shard 2/3: the largest split has 2 shard file(s)") && Contains("no sample") &&
                        Contains("(use at most 2 parts, or a smaller --shard-size)"));
  CHECK_FALSE(std::filesystem::exists(out));
  // Nineteenth campaign F20: parts 0 and 1 of that split were written, though the split could
  // never merge; every part of it is refused.
  for (int i : {0, 1}) {
    auto first = o;
    first.shard_index = i;
    CHECK_THROWS_WITH(heuristic::write_dataset(first, out, nullptr),
                      Contains("--shard " + std::to_string(i) + "/3") && Contains("part 2 would hold no sample"));
  }
  CHECK_FALSE(std::filesystem::exists(out));
  // The advice is one that can be followed (fifteenth campaign F13: "use at most 1 parts", and a
  // smaller --shard-size at 1).
  {
    auto one = o;
    one.count = 1;
    one.val_fraction = 0.0;
    one.test_count = 0;
    one.shard_size = 1;
    one.shard_count = 2;
    one.shard_index = 1;
    CHECK_THROWS_WITH(heuristic::write_dataset(one, out, nullptr), EndsWith("(use at most 1 part)"));
  }
  o.shard_count = 2;  // a split into as many parts as files: every part holds one
  o.shard_index = 1;
  CHECK_NOTHROW(heuristic::write_dataset(o, out, nullptr));
}

TEST_CASE("A dataset folder that contradicts itself is refused naming the file and field",
          "[REQ-HEUR-001][REQ-REPORT-006]") {
  namespace fs = std::filesystem;
  auto o = small_options();
  o.dims = Eigen::Vector3i(8, 8, 4);
  o.shard_count = 2;
  const std::string root = temp_dir() + "/lies";
  fs::remove_all(root);
  const std::string p0 = root + "/p0", p1 = root + "/p1";
  o.shard_index = 0;
  heuristic::write_dataset(o, p0, nullptr);  // train-00000 (2 samples), val-00000, test-00000
  o.shard_index = 1;
  heuristic::write_dataset(o, p1, nullptr);  // train-00001 (1 sample)
  heuristic::merge_dataset_parts({p0, p1}, root + "/honest");
  CHECK(heuristic::read_split(root + "/honest", "train").size() == 3);
  // A part is never read as the dataset, even where a split lies whole in it (p0 holds all of
  // val and test: seventeenth campaign F14 read them as the dataset's).
  for (const char* split : {"val", "test"}) {
    CHECK_THROWS_WITH(heuristic::read_split(p0, split), Contains("is a part of a sharded dataset (part 0/2"));
    CHECK_THROWS_WITH(heuristic::split_samples_held(p0, split), Contains("join the parts with `miner dataset --merge`"));
  }
  // Edits a JSON file of a part; an index edited this way gets its hash in dataset.json
  // recomputed, as a deliberate editor would, so the checks behind the hash are reached.
  const auto edit_json = [](const std::string& path, const auto& change) {
    miner::Json d = miner::read_json_file(path);
    change(d);
    const std::string bytes = miner::dump_json(d);
    miner::write_file_atomic(path, bytes);
    const fs::path file(path);
    const std::string name = file.filename().string(), suffix = "-index.json";
    if (name.size() > suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
      const std::string layout = (file.parent_path() / "dataset.json").string();
      miner::Json doc = miner::read_json_file(layout);
      doc["splits"][name.substr(0, name.size() - suffix.size())]["index_sha256"] = miner::sha256_hex(bytes);
      miner::write_file_atomic(layout, miner::dump_json(doc));
    }
  };
  int n = 0;
  // Copies the honest parts, breaks the copy, and expects the merge to refuse it naming `what`
  // without writing the output folder.
  const auto refused = [&](const auto& break_it, const std::string& what) {
    const std::string q0 = root + "/q0-" + std::to_string(n), q1 = root + "/q1-" + std::to_string(n);
    const std::string out = root + "/out-" + std::to_string(n++);
    fs::copy(p0, q0);
    fs::copy(p1, q1);
    break_it(q0, q1);
    CHECK_THROWS_WITH(heuristic::merge_dataset_parts({q0, q1}, out), Contains(what));
    CHECK_FALSE(fs::exists(out));
    return q0;
  };
  // A part of other options is named by the option and both values (sixth campaign U21: "a part
  // of a different dataset (options differ)").
  refused([&](const std::string&, const std::string& q1) { edit_json(q1 + "/dataset.json", [](miner::Json& d) { d["dilation"] = 3; }); },
          "a part of a different dataset than ");
  refused([&](const std::string&, const std::string& q1) { edit_json(q1 + "/dataset.json", [](miner::Json& d) { d["dims"][2] = 8; }); },
          ": dims[2] is 8 in the one and 4 in the other");
  // A shard name that leaves the folder: neither read nor written outside it.
  fs::copy_file(p0 + "/train-00000.bin", root + "/escape.bin");
  refused(
      [&](const std::string& q0, const std::string&) {
        edit_json(q0 + "/dataset.json", [](miner::Json& d) { d["splits"]["train"]["shards"][0]["file"] = "../escape.bin"; });
      },
      "splits.train.shards[0].file: must be a plain file name");
  // One byte changed, the size kept: the recorded SHA-256 catches it, in a merge and a read.
  const std::string altered = refused(
      [&](const std::string& q0, const std::string&) {
        std::fstream f(q0 + "/train-00000.bin", std::ios::in | std::ios::out | std::ios::binary);
        f.seekp(5);
        f.put('\x07');
      },
      "train-00000.bin: its SHA-256 differs");
  CHECK_THROWS_WITH(heuristic::read_split(altered, "train"), Contains("SHA-256"));
  // Two parts naming the same shard file (part 1's own bytes under part 0's name): the merged
  // folder could hold only one of them.
  refused(
      [&](const std::string&, const std::string& q1) {
        fs::rename(q1 + "/train-00001.bin", q1 + "/train-00000.bin");
        edit_json(q1 + "/dataset.json", [](miner::Json& d) { d["splits"]["train"]["shards"][0]["file"] = "train-00000.bin"; });
      },
      "/dataset.json: splits.train.shards[0].file: \"train-00000.bin\" is named by another part or split too");
  // A misspelt key is not ignored.
  refused(
      [&](const std::string& q0, const std::string&) {
        edit_json(q0 + "/dataset.json", [](miner::Json& d) { d["splits"]["val"]["shard"] = miner::Json::array(); });
      },
      "did you mean \"shards\"");
  // The same sample claimed by both parts (k and its map seed copied from part 0).
  const miner::Json first = miner::read_json_file(p0 + "/train-index.json")[0];
  refused(
      [&](const std::string&, const std::string& q1) {
        edit_json(q1 + "/train-index.json", [&](miner::Json& d) {
          d[0]["k"] = first["k"];
          d[0]["map_seed"] = first["map_seed"];
        });
      },
      "/train-index.json: entry 0 is not sample k = ");
  // Fourteenth campaign C1: a shard renamed (with its dataset.json entry) sorted elsewhere and
  // misaligned every sample with the index; a number past a gap likewise.
  for (const std::string name : {"weird.bin", "train-00007.bin"})
    refused(
        [&](const std::string& q0, const std::string&) {
          fs::rename(q0 + "/train-00000.bin", q0 + "/" + name);
          edit_json(q0 + "/dataset.json", [&](miner::Json& d) { d["splits"]["train"]["shards"][0]["file"] = name; });
        },
        name == "weird.bin" ? "splits.train.shards[0].file: \"weird.bin\" is not a generator's shard name"
                            : "follows no shard train-00000.bin in any part: a shard is missing or renamed");
  // C7: a part made with another --shard-size (here 1: its train-00001.bin holds sample 1,
  // where part 0's shards of 2 put sample 2) is named with the setting, not as a repeated sample.
  refused(
      [&](const std::string&, const std::string& q1) {
        auto other = o;
        other.shard_size = 1;
        other.shard_index = 1;
        fs::remove_all(q1);
        heuristic::write_dataset(other, q1, nullptr);
      },
      "the parts were made with different --shard-size");
  // Values the writer never writes (issue 20: each was read, and bench heuristic measured with
  // it): the format's own fields, the preset's radius, a sample twice in one index, a wrong map
  // seed, goal = start, a cost nothing could have measured.
  const std::vector<std::pair<std::function<void(miner::Json&)>, std::string>> layout_lies{
      {[](miner::Json& d) { d["dtype"] = "float32"; }, "dtype: must be \"uint8\""},
      {[](miner::Json& d) { d["channels"] = {"state", "environment", "target"}; }, "channels: must be"},
      {[](miner::Json& d) { d["robot_radius"] = -1; }, "robot_radius: must be the preset's robot radius"},
      {[](miner::Json& d) { d["preset"] = "forest"; }, "must be the preset's"},
      {[](miner::Json& d) { d["preset"] = "nowhere"; }, "preset:"},
      {[](miner::Json& d) { d["dilation"] = 9; }, "dilation: must be in [0, "},
      {[](miner::Json& d) { d["min_separation"] = -5; }, "min_separation: must be in [0, 1)"}};
  for (const auto& [lie, what] : layout_lies)
    refused([&](const std::string& q0, const std::string&) { edit_json(q0 + "/dataset.json", lie); }, what);
  const std::vector<std::pair<std::function<void(miner::Json&)>, std::string>> index_lies{
      {[](miner::Json& d) { d[1] = d[0]; }, "appears twice"},
      {[](miner::Json& d) { d[0]["map_seed"] = d[0]["map_seed"].get<std::uint64_t>() ^ 1u; }, "map_seed: is not splitmix64"},
      {[](miner::Json& d) { d[0]["goal"] = d[0]["start"]; }, "goal: is the start"},
      {[](miner::Json& d) { d[0]["astar_cost"] = 1e300; }, "over 1000 times the bounds' diagonal"}};
  for (const auto& [lie, what] : index_lies)
    refused([&](const std::string& q0, const std::string&) { edit_json(q0 + "/train-index.json", lie); }, what);
  // Fourteenth campaign C5: an index edited in a part (an entry's bounds or start moved) merged
  // unnoticed; dataset.json now records each index file's SHA-256 like each shard's.
  const std::string moved = refused(
      [&](const std::string& q0, const std::string&) {
        miner::Json d = miner::read_json_file(q0 + "/train-index.json");
        d[0]["bounds"]["max"][0] = d[0]["bounds"]["max"][0].get<double>() + 1.0;
        miner::write_file_atomic(q0 + "/train-index.json", miner::dump_json(d));
      },
      "train-index.json: its SHA-256 differs from the one dataset.json records");
  CHECK_THROWS_WITH(heuristic::read_split(moved, "train"), Contains("train-index.json: its SHA-256 differs"));
  refused([&](const std::string& q0, const std::string&) {
    edit_json(q0 + "/dataset.json", [](miner::Json& d) { d["splits"]["val"].erase("index_sha256"); });
  }, "splits.val.index_sha256: missing required field");
  refused([&](const std::string& q0, const std::string&) {
    edit_json(q0 + "/dataset.json", [](miner::Json& d) { d["splits"]["val"]["index_sha256"] = "ABC"; });
  }, "splits.val.index_sha256: must be 64 lower-case hexadecimal digits");
  // A folder of the format before the hashes is named as such, not read with its index unchecked.
  refused([&](const std::string& q0, const std::string&) {
    edit_json(q0 + "/dataset.json", [](miner::Json& d) { d["format"] = "miner-dataset-v2"; });
  }, "\"miner-dataset-v2\" was written by an earlier miner (v1 had no channel P, v2 no hash of its index files)");
  // The merged folder's index files are hashed too: what merges reads back (the honest merge
  // above), and its dataset.json names the merged index's hash, not a part's.
  {
    const miner::Json merged = miner::read_json_file(root + "/honest/dataset.json");
    CHECK(merged["splits"]["train"]["index_sha256"] == miner::sha256_hex(read_bytes(root + "/honest/train-index.json")));
    CHECK(merged["splits"]["train"]["index_sha256"] != miner::read_json_file(p0 + "/dataset.json")["splits"]["train"]["index_sha256"]);
  }
  // An index that does not match its shards.
  refused(
      [&](const std::string& q0, const std::string&) {
        edit_json(q0 + "/train-index.json", [](miner::Json& d) { d.erase(d.size() - 1); });
      },
      "train-index.json: (top level): has 1 entries, the shards 2 samples");
  // An output folder that is or holds a part: refused, the parts kept.
  CHECK_THROWS_WITH(heuristic::merge_dataset_parts({p0, p1}, root), Contains("is or holds the part"));
  CHECK_THROWS_WITH(heuristic::merge_dataset_parts({p0, p1}, p0), Contains("is or holds the part"));
  CHECK_THROWS_WITH(heuristic::merge_dataset_parts({p0, p1}, p1 + "/sub"), Contains("lies inside the part"));
  CHECK_FALSE(std::filesystem::exists(p1 + "/sub"));
  CHECK(fs::exists(p0 + "/dataset.json"));
  CHECK(fs::exists(p1 + "/dataset.json"));
  // A negative map seed (nlohmann would wrap it on reading).
  refused(
      [&](const std::string& q0, const std::string&) {
        edit_json(q0 + "/test-index.json", [](miner::Json& d) { d[0]["map_seed"] = -1; });
      },
      "map_seed: expected an integer in [0, 2^64 - 1]");
  // A path shorter than the straight line (issue 20: a cost of -5 merged).
  refused(
      [&](const std::string& q0, const std::string&) {
        edit_json(q0 + "/train-index.json", [](miner::Json& d) { d[0]["astar_cost"] = -5; });
      },
      "astar_cost: is -5, shorter than the straight line from start to goal");
  // The map's bounds (the sGAN's scale input, REQ-HEUR-013): missing, empty, or not holding
  // the query.
  refused(
      [&](const std::string& q0, const std::string&) {
        edit_json(q0 + "/train-index.json", [](miner::Json& d) { d[0].erase("bounds"); });
      },
      "bounds");
  refused(
      [&](const std::string& q0, const std::string&) {
        edit_json(q0 + "/train-index.json", [](miner::Json& d) { d[0]["bounds"]["max"][2] = -1.0; });
      },
      "min must be below max");
  refused(
      [&](const std::string& q0, const std::string&) {
        edit_json(q0 + "/train-index.json", [](miner::Json& d) { d[0]["start"][0] = 1e6; });
      },
      "start: lies outside the sample's bounds");
  refused(  // the goal is checked by itself, not through the start (held-out audit 7, h7-heuristic-04)
      [&](const std::string& q0, const std::string&) {
        edit_json(q0 + "/train-index.json", [](miner::Json& d) { d[0]["goal"][1] = -1e6; });
      },
      "goal: lies outside the sample's bounds");
  // Shard bytes outside their levels, or a sample with no start and goal cells, with the SHA-256
  // in dataset.json recomputed to match (issue 20, sixth campaign: they were read silently).
  const auto edit_shard = [&](const std::string& q0, const std::function<void(std::string&)>& change) {
    const std::string shard = q0 + "/train-00000.bin";
    std::string bytes;
    {
      std::ifstream in(shard, std::ios::binary);
      bytes.assign(std::istreambuf_iterator<char>(in), {});
    }
    change(bytes);
    miner::write_file_atomic(shard, bytes);
    edit_json(q0 + "/dataset.json",
              [&](miner::Json& d) { d["splits"]["train"]["shards"][0]["sha256"] = miner::sha256_hex(bytes); });
  };
  const std::size_t cells = 8 * 8 * 4;
  refused([&](const std::string& q0, const std::string&) { edit_shard(q0, [](std::string& b) { b[5] = 9; }); },
          "train-00000.bin: sample 0 of the shard, channel environment, cell 5: holds 9, outside its levels 0..2");
  refused(
      [&](const std::string& q0, const std::string&) {
        edit_shard(q0, [&](std::string& b) { b[4 * cells + 3 * cells + 7] = static_cast<char>(8); });
      },
      "sample 1 of the shard, channel passability, cell 7: holds 8, outside its levels 0..7");
  refused(
      [&](const std::string& q0, const std::string&) {
        edit_shard(q0, [&](std::string& b) { std::fill(b.begin() + cells, b.begin() + 2 * cells, '\0'); });
      },
      "sample 0 of the shard, channel state: marks no cell");
  // The target channel too (held-out audit 11, h11-heuristic-05: only S was tried).
  refused(
      [&](const std::string& q0, const std::string&) {
        edit_shard(q0, [&](std::string& b) { std::fill(b.begin() + 2 * cells, b.begin() + 3 * cells, '\0'); });
      },
      "sample 0 of the shard, channel target: marks no cell");
  // Fourteenth campaign C1: a shard holding other samples than its index (here its two samples
  // swapped), re-hashed, was merged; the state channel must mark each entry's start and goal.
  refused(
      [&](const std::string& q0, const std::string&) {
        edit_shard(q0, [&](std::string& b) {
          const std::size_t sample = 4 * cells;
          std::swap_ranges(b.begin(), b.begin() + static_cast<std::ptrdiff_t>(sample), b.begin() + static_cast<std::ptrdiff_t>(sample));
        });
      },
      "train-00000.bin: sample 0 (k = 0, ");
}

TEST_CASE("A dataset folder of an earlier format is regenerated in place, a user's folder is not replaced",
          "[REQ-HEUR-001]") {
  // miner-dataset-v3 (session 35) hashes the index files; a v2 folder is read no more, so the
  // natural fix, `miner dataset --out` over it, must be allowed.
  const auto o = small_options();
  const std::string dir = temp_dir() + "/earlier";
  heuristic::write_dataset(o, dir, nullptr);
  miner::Json doc = miner::read_json_file(dir + "/dataset.json");
  doc["format"] = "miner-dataset-v2";
  miner::write_file_atomic(dir + "/dataset.json", miner::dump_json(doc));
  // A v2 folder was written before folders carried SHA256SUMS.
  REQUIRE(std::filesystem::remove(dir + "/" + miner::kFolderManifest));
  CHECK_THROWS_WITH(heuristic::read_split(dir, "train"), Contains("written by an earlier miner"));
  CHECK_NOTHROW(heuristic::write_dataset(o, dir, nullptr));
  CHECK(miner::read_json_file(dir + "/dataset.json")["format"] == heuristic::kDatasetFormat);
  CHECK(heuristic::read_split(dir, "train").size() == 3);
  doc["format"] = "my-own-notes";
  miner::write_file_atomic(dir + "/dataset.json", miner::dump_json(doc));
  CHECK_THROWS_WITH(heuristic::write_dataset(o, dir, nullptr), Contains("is not an earlier output of this command"));
  REQUIRE(std::filesystem::remove(dir + "/" + miner::kFolderManifest));
  CHECK_THROWS_WITH(heuristic::write_dataset(o, dir, nullptr), Contains("is not a \"miner-dataset-v3\" file"));
}

TEST_CASE("A whole dataset (--shard 0/1) merges on its own into the same bytes", "[REQ-REPORT-006]") {
  // Fifteenth campaign F5: `dataset --shard 0/1` wrote the unsharded folder, which `--merge`
  // refused as "not a part folder", so an array job of N = 1 could not merge its own output.
  const auto o = small_options();  // shard 0 of 1
  const std::string whole = temp_dir() + "/whole", out = temp_dir() + "/whole-merged";
  std::filesystem::remove_all(out);
  heuristic::write_dataset(o, whole, nullptr);
  heuristic::merge_dataset_parts({whole}, out);
  for (const char* f : {"dataset.json", "train-00000.bin", "train-00001.bin", "val-00000.bin", "test-00000.bin",
                        "train-index.json", "val-index.json", "test-index.json"})
    CHECK(read_bytes(out + "/" + f) == read_bytes(whole + "/" + f));
  // Beside a part it is not a part.
  auto part = o;
  part.shard_count = 2;
  part.shard_index = 1;
  const std::string p1 = temp_dir() + "/part-1-of-2";
  heuristic::write_dataset(part, p1, nullptr);
  CHECK_THROWS_WITH(heuristic::merge_dataset_parts({whole, p1}, temp_dir() + "/mixed"),
                    Contains("whole: not a part folder (made without --shard, or with --shard 0/1)"));
}

TEST_CASE("Bad dataset options are refused naming the option", "[REQ-HEUR-003]") {
  auto o = small_options();
  o.count = 0;
  CHECK_THROWS_WITH(heuristic::write_dataset(o, temp_dir() + "/bad", nullptr), Contains("--count"));
  o = small_options();
  o.dims = Eigen::Vector3i(2, 32, 32);
  CHECK_THROWS_WITH(heuristic::validate(o), Contains("--dims"));
  // Both ends of --dims [4, 256] are kept, a cell past each refused (held-out audit 7,
  // h7-heuristic-02 refused 4).
  for (const int n : {4, 256}) {
    o.dims = Eigen::Vector3i(n, n, 4);
    CHECK_NOTHROW(heuristic::validate(o));
  }
  for (const int n : {3, 257}) {
    o.dims = Eigen::Vector3i(8, 8, n);
    CHECK_THROWS_WITH(heuristic::validate(o), Contains("--dims"));
  }
  // A validation share that rounds to every sample leaves none for training and is refused; one
  // sample fewer is kept (held-out audit 11, h11-heuristic-03: ">" let 0.99 of 2 write 0).
  o = small_options();
  o.count = 2;
  o.val_fraction = 0.99;  // rounds to 2 of 2
  CHECK_THROWS_WITH(heuristic::validate(o), Contains("keeps every sample for validation"));
  o.val_fraction = 0.74;  // rounds to 1 of 2
  CHECK_NOTHROW(heuristic::validate(o));
  o = small_options();
  o.preset = "swamp";
  CHECK_THROWS_WITH(heuristic::validate(o), Contains("swamp"));
  o = small_options();
  o.jobs = 0;
  CHECK_THROWS_WITH(heuristic::validate(o), Contains("--jobs must be in [1, 256]"));
  // The range's ends are in it (held-out set 12, h12-heur-06: 256 was refused).
  for (int jobs : {1, 256}) {
    o.jobs = jobs;
    CHECK_NOTHROW(heuristic::validate(o));
  }
  o.jobs = 257;
  CHECK_THROWS_WITH(heuristic::validate(o), Contains("--jobs must be in [1, 256]"));
  // Bounded output, refused before any sample (issue 20: 5e14 bytes were attempted).
  o = small_options();
  o.count = 10000000;
  o.dims = Eigen::Vector3i(256, 256, 256);
  CHECK_THROWS_WITH(heuristic::validate(o), Contains("more than the 2.74878e+11 (256 GiB) a dataset may have"));
  CHECK_FALSE(std::filesystem::exists(temp_dir() + "/bad"));
}

TEST_CASE("The progress bar draws only to a given stream and ends its line", "[REQ-CORE-006]") {
  std::ostringstream os;
  {
    miner::ProgressBar bar(&os, "work", 4);
    bar.update(1);
    CHECK_THAT(os.str(), Contains("1/4") && Contains(" s, ETA "));  // elapsed and the rest
    for (std::size_t i = 2; i <= 4; ++i) bar.update(i);
  }
  CHECK_THAT(os.str(), Contains("work [") && Contains("4/4"));
  CHECK(os.str().back() == '\n');
  miner::ProgressBar quiet(nullptr, "work", 4);
  quiet.update(2);  // no stream: nothing happens, nothing crashes
}

TEST_CASE("Channel S is exactly the clipped cubes around the start and goal cells", "[REQ-HEUR-002]") {
  // Held-out audit 5 (h5-heur-04): S losing the cubes' top layer kept 27 <= count <= 54.
  namespace h = miner::heuristic;
  const miner::world::Box bounds{{0, 0, 0}, {8, 8, 8}};
  const Eigen::Vector3i dims(8, 8, 8);
  for (const auto& [start, goal] : {std::pair{Eigen::Vector3d(1.5, 1.5, 1.5), Eigen::Vector3d(6.5, 6.5, 6.5)},
                                    std::pair{Eigen::Vector3d(0.5, 3.5, 0.5), Eigen::Vector3d(7.5, 7.5, 7.5)}}) {
    const std::vector<std::uint8_t> s = h::encode_state(bounds, dims, start, goal, 1);
    for (int k = 0; k < 8; ++k)
      for (int j = 0; j < 8; ++j)
        for (int i = 0; i < 8; ++i) {
          const Eigen::Vector3i c(i, j, k);
          const auto near = [&](const Eigen::Vector3d& p) {
            return ((c - p.cast<int>()).cwiseAbs().array() <= 1).all();  // cells of 1 m: floor of p
          };
          INFO(i << " " << j << " " << k);
          CHECK((s[h::cell_index(dims, i, j, k)] != 0) == (near(start) || near(goal)));
        }
  }
}

TEST_CASE("A cell whose faces lie on a single grown box's faces is solid", "[REQ-HEUR-002][REQ-HEUR-012]") {
  // Held-out audit 5 (h5-heur-02): a cell whose top face lies exactly on the box's top face was
  // counted partial; solid cells in the other tests lay strictly inside boxes.
  namespace h = miner::heuristic;
  const miner::world::Map map(miner::world::Box{{0, 0, 0}, {4, 4, 4}}, 1.0, {miner::world::Box{{0, 0, 0}, {2, 2, 2}}});
  const Eigen::Vector3i dims(4, 4, 4);
  const std::vector<std::uint8_t> e = h::encode_environment(map, dims, 0.0);
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) CHECK(e[h::cell_index(dims, i, j, k)] == h::kSolid);
  CHECK(e[h::cell_index(dims, 3, 3, 3)] == h::kFree);
}

TEST_CASE("A sample whose bytes differ from the generator's is refused naming the channel and cell", "[REQ-HEUR-001][REQ-REPORT-006]") {
  // Issue 20, seventh campaign W2: T edited within its levels, the SHA-256 recomputed, was
  // measured as the truth.
  auto o = small_options();
  o.dims = Eigen::Vector3i(8, 8, 4);
  const std::string dir = temp_dir() + "/verify";
  std::filesystem::remove_all(dir);
  heuristic::write_dataset(o, dir, nullptr);
  std::vector<heuristic::Sample> test = heuristic::read_split(dir, "test");
  REQUIRE(test.size() == 1);
  CHECK(test[0].k == 4);  // test samples follow the count
  CHECK_NOTHROW(heuristic::verify_samples(dir, test));
  auto edited = test;
  const std::size_t cell = heuristic::cell_index(o.dims, 3, 2, 1);
  edited[0].target[cell] ^= 1;
  CHECK_THROWS_WITH(heuristic::verify_samples(dir, edited),
                    Contains("sample k = 4: channel target at cell (3, 2, 1) holds") && Contains("regenerated"));
  edited = test;
  edited[0].environment[0] = edited[0].environment[0] == 0 ? 1 : 0;
  CHECK_THROWS_WITH(heuristic::verify_samples(dir, edited), Contains("channel environment at cell (0, 0, 0)"));
  edited = test;
  edited[0].astar_cost += 1.0;
  CHECK_THROWS_WITH(heuristic::verify_samples(dir, edited), Contains("its index entry"));
  // Fourteenth campaign C5: the bounds were not compared (training reads sigma from them).
  edited = test;
  edited[0].bounds.max.x() += 1.0;
  CHECK_THROWS_WITH(heuristic::verify_samples(dir, edited), Contains("sample k = 4: its index entry's bounds"));
}

TEST_CASE("The validation split is the fraction rounded to whole samples, not truncated", "[REQ-HEUR-001]") {
  // Held-out audit 8, h8-heuristic-05: 0.5 of 3 samples gave 1 validation sample (truncated)
  // instead of 2 (rounded, as the check against an empty training split counts it).
  auto o = small_options();
  o.count = 3;
  o.val_fraction = 0.5;
  o.test_count = 0;
  const miner::Json doc = heuristic::write_dataset(o, temp_dir() + "/rounded", nullptr);
  CHECK(doc["splits"]["val"]["count"] == 2);
  CHECK(doc["splits"]["train"]["count"] == 1);
}

TEST_CASE("Any two 26-neighbour cells connect wherever they lie in the grid including its faces edges and corners",
          "[REQ-HEUR-004][REQ-HEUR-007]") {
  // Held-out audit 9, h9-heuristic-03: on cells of the grid's border, component_of never stepped down
  // from z = 1 to z = 0, so a region chain along a face through z = 0 was reported as not connected.
  for (const Eigen::Vector3i& d : {Eigen::Vector3i(4, 4, 4), Eigen::Vector3i(3, 5, 4)}) {
    int pairs = 0, failures = 0;
    for (int z = 0; z < d.z(); ++z)
      for (int y = 0; y < d.y(); ++y)
        for (int x = 0; x < d.x(); ++x)
          for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
              for (int dx = -1; dx <= 1; ++dx) {
                const Eigen::Vector3i a(x, y, z), b(x + dx, y + dy, z + dz);
                if ((a == b) || (b.array() < 0).any() || (b.array() >= d.array()).any()) continue;
                std::vector<std::uint8_t> m(static_cast<std::size_t>(d.prod()), 0);
                m[heuristic::cell_index(d, a.x(), a.y(), a.z())] = 1;
                m[heuristic::cell_index(d, b.x(), b.y(), b.z())] = 1;
                ++pairs;
                if (!heuristic::connects(m, d, a, b)) {
                  ++failures;
                  UNSCOPED_INFO("(" << a.transpose() << ") -> (" << b.transpose() << ") not connected");
                }
              }
    CHECK(pairs > 0);
    CHECK(failures == 0);
  }
  // The audit's input: only (0,0,0) and (0,0,1) of a 4^3 grid, both ways.
  const Eigen::Vector3i d(4, 4, 4);
  std::vector<std::uint8_t> m(64, 0);
  m[heuristic::cell_index(d, 0, 0, 0)] = m[heuristic::cell_index(d, 0, 0, 1)] = 1;
  CHECK(heuristic::connects(m, d, {0, 0, 1}, {0, 0, 0}));
  CHECK(heuristic::connects(m, d, {0, 0, 0}, {0, 0, 1}));
}

TEST_CASE("A dataset part whose index equals its part count is refused naming the part", "[REQ-REPORT-006][REQ-HEUR-001]") {
  // Held-out audit 9, h9-heuristic-06: dataset.json's part {index, count} was checked with index > count,
  // so a part {index: 2, count: 2} was read and merged instead of refused.
  namespace fs = std::filesystem;
  auto o = small_options();
  o.dims = Eigen::Vector3i(8, 8, 4);
  o.shard_count = 2;
  const std::string root = temp_dir() + "/part-index";
  fs::remove_all(root);
  const std::string p0 = root + "/p0", p1 = root + "/p1";
  o.shard_index = 0;
  heuristic::write_dataset(o, p0, nullptr);
  o.shard_index = 1;
  heuristic::write_dataset(o, p1, nullptr);
  REQUIRE(miner::read_json_file(p1 + "/dataset.json")["part"]["index"] == 1);  // the last index, kept
  heuristic::merge_dataset_parts({p0, p1}, root + "/honest");
  for (const int index : {2, 3, -1}) {
    const std::string q1 = root + "/q1-" + std::to_string(index + 1), out = root + "/out-" + std::to_string(index + 1);
    fs::copy(p1, q1);
    miner::Json d = miner::read_json_file(q1 + "/dataset.json");
    d["part"]["index"] = index;
    miner::write_file_atomic(q1 + "/dataset.json", miner::dump_json(d));
    INFO("part.index " << index);
    // Read alone (split_samples_held reads dataset.json as read_split does) and merged: the field is named.
    CHECK_THROWS_WITH(heuristic::split_samples_held(q1, "train"), Contains(q1 + "/dataset.json: part: needs 0 <= index < count"));
    CHECK_THROWS_WITH(heuristic::merge_dataset_parts({p0, q1}, out),
                      Contains("dataset.json") && Contains("part: needs 0 <= index < count"));
    CHECK_FALSE(fs::exists(out));
  }
}

TEST_CASE("A part whose channels contradict its index entry or REQ-HEUR-002 is refused, re-hashed or not",
          "[REQ-HEUR-001][REQ-HEUR-002][REQ-REPORT-006]") {
  // Fifteenth campaign F1: with the shard's SHA-256 recomputed, a T without its start cell, an S
  // of all ones, P 0 on a free cell or an E solid on the start merged silently. Each is
  // checkable from the sample's own index entry and channels (check_sample_channels).
  namespace fs = std::filesystem;
  auto o = small_options();
  o.dims = Eigen::Vector3i(16, 16, 8);
  o.shard_count = 2;
  const std::string root = temp_dir() + "/channels";
  fs::remove_all(root);
  const std::string p0 = root + "/p0", p1 = root + "/p1";
  o.shard_index = 0;
  heuristic::write_dataset(o, p0, nullptr);
  o.shard_index = 1;
  heuristic::write_dataset(o, p1, nullptr);
  heuristic::merge_dataset_parts({p0, p1}, root + "/honest");
  const heuristic::Sample s0 = heuristic::read_split(root + "/honest", "train").at(0);  // k = 0: p0's first
  REQUIRE(s0.k == 0);
  const std::size_t cells = static_cast<std::size_t>(o.dims.prod());
  const auto index_of = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector3i c = heuristic::cell_of(s0.bounds, o.dims, p);
    return heuristic::cell_index(o.dims, c.x(), c.y(), c.z());
  };
  const std::size_t start = index_of(s0.start), goal = index_of(s0.goal);
  // A free cell off T farther than the dilation from every T cell, and a free cell in none.
  std::size_t far = cells, free_cell = cells;
  for (std::size_t i = 0; i < cells; ++i) {
    if (s0.environment[i] != heuristic::kFree) continue;
    if (free_cell == cells) free_cell = i;
    const Eigen::Vector3i c = heuristic::cell_coords(o.dims, i);
    bool near = false;
    for (std::size_t j = 0; j < cells && !near; ++j)
      near = s0.target[j] && (heuristic::cell_coords(o.dims, j) - c).cwiseAbs().maxCoeff() <= o.dilation;
    if (!near) {
      far = i;
      break;
    }
  }
  REQUIRE(far < cells);
  REQUIRE(free_cell < cells);
  int n = 0;
  const auto refused = [&](const std::function<void(std::string&)>& change, const std::string& what) {
    const std::string q0 = root + "/q0-" + std::to_string(n), q1 = root + "/q1-" + std::to_string(n);
    const std::string out = root + "/out-" + std::to_string(n++);
    fs::copy(p0, q0);
    fs::copy(p1, q1);
    const std::string shard = q0 + "/train-00000.bin";
    std::string bytes = read_bytes(shard);
    change(bytes);
    miner::write_file_atomic(shard, bytes);
    miner::Json doc = miner::read_json_file(q0 + "/dataset.json");
    doc["splits"]["train"]["shards"][0]["sha256"] = miner::sha256_hex(bytes);
    miner::write_file_atomic(q0 + "/dataset.json", miner::dump_json(doc));
    CHECK_THROWS_WITH(heuristic::merge_dataset_parts({q0, q1}, out), Contains("train-00000.bin: sample 0 (k = 0, ") && Contains(what));
    CHECK_FALSE(fs::exists(out));
  };
  const auto E = [](std::string& b, std::size_t i) -> char& { return b[i]; };
  const auto S = [&](std::string& b, std::size_t i) -> char& { return b[cells + i]; };
  const auto T = [&](std::string& b, std::size_t i) -> char& { return b[2 * cells + i]; };
  const auto P = [&](std::string& b, std::size_t i) -> char& { return b[3 * cells + i]; };
  refused([&](std::string& b) { T(b, start) = 0; }, "channel target does not mark the start cell");
  refused([&](std::string& b) { T(b, goal) = 0; }, "channel target does not mark the goal cell");
  refused([&](std::string& b) { for (std::size_t i = 0; i < cells; ++i) S(b, i) = 1; }, "channel state at cell");
  refused([&](std::string& b) { S(b, far) = 1; }, "channel state at cell");
  refused([&](std::string& b) { P(b, free_cell) = 0; }, "on a free cell");
  refused([&](std::string& b) { P(b, free_cell) = heuristic::kPassX; }, "on a free cell");
  refused([&](std::string& b) { E(b, far) = heuristic::kSolid; }, "on a solid cell");
  refused([&](std::string& b) { E(b, start) = heuristic::kSolid; P(b, start) = 0; }, "marks a solid cell");
  refused([&](std::string& b) { E(b, start) = heuristic::kSolid; P(b, start) = 0; T(b, start) = 0; },
          "channel environment marks the start cell");
  refused([&](std::string& b) { T(b, far) = 1; }, "lies more than the dilation");
  // A T cut between start and goal: every T cell but the start's own cube cleared.
  refused(
      [&](std::string& b) {
        const Eigen::Vector3i c = heuristic::cell_coords(o.dims, start);
        for (std::size_t i = 0; i < cells; ++i)
          if ((heuristic::cell_coords(o.dims, i) - c).cwiseAbs().maxCoeff() > 1 && i != goal) T(b, i) = 0;
      },
      "channel target does not join the start");
  // The readers check the same: a whole folder edited and re-hashed is refused by read_split.
  const std::string whole = root + "/whole";
  fs::copy(root + "/honest", whole);
  std::string bytes = read_bytes(whole + "/train-00000.bin");
  P(bytes, free_cell) = 0;
  miner::write_file_atomic(whole + "/train-00000.bin", bytes);
  miner::Json doc = miner::read_json_file(whole + "/dataset.json");
  doc["splits"]["train"]["shards"][0]["sha256"] = miner::sha256_hex(bytes);
  miner::write_file_atomic(whole + "/dataset.json", miner::dump_json(doc));
  CHECK_THROWS_WITH(heuristic::read_split(whole, "train"), Contains("train-00000.bin: sample 0 (k = 0)") && Contains("on a free cell"));
  // Every sample the generator writes passes the checks, in every preset, at dilations 0-2 in
  // turn (each preset at one: the sweep of all three took 20 s).
  int turn = 0;
  for (const std::string& preset : miner::world::generator_preset_names())
    for (int dilation : {turn++ % 3}) {
      auto g = small_options();
      g.count = 2;
      g.preset = preset;
      g.dilation = dilation;
      g.dims = Eigen::Vector3i(16, 16, 8);
      const std::string dir = root + "/gen-" + preset + std::to_string(dilation);
      INFO(dir);
      heuristic::write_dataset(g, dir, nullptr);
      CHECK_NOTHROW(heuristic::merge_dataset_parts({dir}, dir + "-merged"));
      for (const char* split : {"train", "val", "test"}) CHECK_NOTHROW(heuristic::read_split(dir, split));
    }
}

TEST_CASE("The grid helpers refuse a grid without cells or bounds without extent, naming both",
          "[REQ-HEUR-002][REQ-HEUR-004]") {
  // Fifteenth campaign F9: zero-extent bounds gave cell_of (2, 2, INT_MIN) (a NaN cast to int),
  // dims 0 a cell (-1, 5, 5) "clamped onto the grid", and encode_state an all-zero S.
  const miner::world::Box good{{0, 0, 0}, {10, 10, 10}};
  const Eigen::Vector3d p(5, 5, 5), q(8, 8, 8);
  const miner::world::Box flat{{0, 0, 0}, {10, 10, 0}};
  const miner::world::Box inverted{{0, 0, 0}, {10, -10, 10}};
  for (const auto& [bounds, dims] : {std::pair{flat, Eigen::Vector3i(4, 4, 4)}, std::pair{inverted, Eigen::Vector3i(4, 4, 4)},
                                    std::pair{good, Eigen::Vector3i(0, 4, 4)}, std::pair{good, Eigen::Vector3i(4, -1, 4)}}) {
    CHECK_THROWS_WITH(heuristic::cell_of(bounds, dims, p),
                      Contains("cells over the bounds") && Contains("needs at least one cell per axis"));
    CHECK_THROWS_WITH(heuristic::cell_box(bounds, dims, Eigen::Vector3i(0, 0, 0)), Contains("cells over the bounds"));
    CHECK_THROWS_WITH(heuristic::encode_state(bounds, dims, p, q, 1),
                      Contains("cells over the bounds") || Contains("dims: every entry must be >= 1"));
  }
  const miner::world::Box huge{{-1e308, 0, 0}, {1e308, 10, 10}};  // its extent overflows
  CHECK_THROWS_WITH(heuristic::cell_size(huge, Eigen::Vector3i(4, 4, 4)), Contains("finite"));
  // The helpers still place every point of a valid grid on it, clamped.
  CHECK(heuristic::cell_of(good, Eigen::Vector3i(4, 4, 4), Eigen::Vector3d(-5, 5, 50)) == Eigen::Vector3i(0, 2, 3));
}
