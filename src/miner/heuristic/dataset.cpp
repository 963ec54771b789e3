#include "miner/heuristic/dataset.hpp"

#include <atomic>
#include <exception>
#include <mutex>
#include <thread>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "miner/core/error.hpp"
#include "miner/core/progress.hpp"
#include "miner/core/rng.hpp"
#include "miner/core/shard.hpp"
#include "miner/heuristic/grid.hpp"
#include "miner/plan/heuristic_region.hpp"
#include "miner/world/astar.hpp"
#include "miner/world/map_generator.hpp"
#include "miner/world/voxel_grid.hpp"

namespace miner::heuristic {

namespace {

/// Start/goal draws per map before falling back to the map's own (A*-checked) query.
constexpr int kMaxQueryAttempts = 64;
constexpr const char* kSplits[3] = {"train", "val", "test"};

std::string shard_name(const std::string& split, std::size_t i) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%s-%05zu.bin", split.c_str(), i);
  return buf;
}

}  // namespace

void validate(const DatasetOptions& o) {
  world::generator_preset(o.preset);  // throws naming the known presets
  if (o.count < 1) throw Error("dataset: --count must be >= 1");
  if (o.test_count < 0) throw Error("dataset: --test-count must be >= 0");
  if (!(o.val_fraction >= 0.0 && o.val_fraction < 1.0)) throw Error("dataset: --val-fraction must be in [0, 1)");
  if ((o.dims.array() < 4).any() || (o.dims.array() > 256).any())
    throw Error("dataset: --dims must be between 4 and 256 cells per axis");
  if (o.dilation < 0 || o.dilation > 4) throw Error("dataset: --dilation must be in [0, 4]");
  if (o.shard_size < 1) throw Error("dataset: --shard-size must be >= 1");
  if (o.jobs < 1 || o.jobs > 256) throw Error("dataset: --jobs must be in [1, 256]");
  require_shard(o.shard_index, o.shard_count);
  if (!(o.min_separation >= 0.0 && o.min_separation < 1.0)) throw Error("dataset: min_separation must be in [0, 1)");
}

Sample make_sample(const DatasetOptions& o, std::uint64_t k) {
  const world::GeneratorPreset preset = world::generator_preset(o.preset);
  Sample s;
  s.map_seed = splitmix64(o.seed ^ k);
  const world::Map map = world::generate_map(preset, s.map_seed);
  const double r = preset.robot_radius;
  const world::VoxelGrid grid(map, r);
  const world::Box& b = map.bounds();
  const double min_distance = o.min_separation * (b.max - b.min).norm();
  Rng rng(s.map_seed, 0x9e3779b97f4a7c15ULL);  // a stream the generator never uses
  std::optional<world::GridPath> path;
  for (int attempt = 0; attempt < kMaxQueryAttempts && !path; ++attempt) {
    Eigen::Vector3d p[2];
    for (auto& q : p)
      for (int a = 0; a < 3; ++a) q[a] = rng.uniform(b.min[a] + r, b.max[a] - r);
    if ((p[1] - p[0]).norm() < min_distance || !map.is_free(p[0], r) || !map.is_free(p[1], r)) continue;
    try {
      path = world::astar(map, grid, p[0], p[1]);
      s.start = p[0];
      s.goal = p[1];
    } catch (const Error&) {
      // an occupied grid cell or no grid path: draw again
    }
  }
  if (!path) {  // the generator's own query is solvable by construction
    s.start = map.query()->start;
    s.goal = map.query()->goal;
    path = world::astar(map, grid, s.start, s.goal);
  }
  s.astar_cost = path->cost;
  s.environment = encode_environment(map, o.dims, r);
  s.state = encode_state(b, o.dims, s.start, s.goal, o.dilation);
  const auto region = plan::HeuristicRegion::from_path(b, o.dims, path->points, o.dilation, "astar-dilated");
  // T leaves out the solid cells the dilation reaches into (no free point there); the path's
  // own cells are never solid, so T stays connected.
  s.target.assign(static_cast<std::size_t>(o.dims.prod()), 0);
  for (std::size_t c : region.cells()) s.target[c] = s.environment[c] == kSolid ? 0 : 1;
  return s;
}

Json write_dataset(const DatasetOptions& o, const std::string& dir, std::ostream* progress) {
  validate(o);
  const int val = static_cast<int>(std::lround(o.val_fraction * o.count));
  const int counts[3] = {o.count - val, val, o.test_count};
  const std::uint64_t first[3] = {0, static_cast<std::uint64_t>(o.count - val), static_cast<std::uint64_t>(o.count)};
  const std::size_t cells = static_cast<std::size_t>(o.dims.prod());
  std::vector<std::pair<std::string, std::string>> files;
  Json splits = Json::object();
  ProgressBar bar(progress, "dataset", static_cast<std::size_t>(o.count + o.test_count));
  std::size_t done = 0;
  for (int sp = 0; sp < 3; ++sp) {
    Json shards = Json::array();
    Json index = Json::array();
    std::string shard;
    int in_shard = 0;
    int file_number = 0;
    auto flush = [&] {
      if (in_shard == 0) return;
      const std::string name = shard_name(kSplits[sp], static_cast<std::size_t>(file_number));
      shards.push_back({{"file", name}, {"count", in_shard}});
      files.emplace_back(name, std::move(shard));
      shard.clear();
      in_shard = 0;
    };
    // Samples are independent, so `jobs` threads make a shard's worth at a time; the bytes
    // do not depend on the number of threads.
    for (int i0 = 0; i0 < counts[sp]; i0 += o.shard_size) {
      const int n = std::min(o.shard_size, counts[sp] - i0);
      file_number = i0 / o.shard_size;
      if (file_number % o.shard_count != o.shard_index) {  // another part's file
        done += static_cast<std::size_t>(n);
        bar.update(done);
        continue;
      }
      std::vector<Sample> batch(static_cast<std::size_t>(n));
      std::atomic<int> next{0};
      std::exception_ptr failure;
      std::mutex failure_mutex;
      auto worker = [&] {
        for (int i = next++; i < n; i = next++) {
          try {
            batch[static_cast<std::size_t>(i)] = make_sample(o, first[sp] + static_cast<std::uint64_t>(i0 + i));
          } catch (...) {
            const std::lock_guard<std::mutex> lock(failure_mutex);
            if (!failure) failure = std::current_exception();
          }
        }
      };
      std::vector<std::thread> pool;
      for (int t = 1; t < std::min(o.jobs, n); ++t) pool.emplace_back(worker);
      worker();
      for (auto& t : pool) t.join();
      if (failure) std::rethrow_exception(failure);
      for (int i = 0; i < n; ++i) {
        const Sample& s = batch[static_cast<std::size_t>(i)];
        for (const auto* channel : {&s.environment, &s.state, &s.target})
          shard.append(reinterpret_cast<const char*>(channel->data()), cells);
        index.push_back({{"k", first[sp] + static_cast<std::uint64_t>(i0 + i)}, {"map_seed", s.map_seed},
                         {"start", vec3_json(s.start)}, {"goal", vec3_json(s.goal)}, {"astar_cost", s.astar_cost}});
        if (++in_shard == o.shard_size) flush();
      }
      done += static_cast<std::size_t>(n);
      bar.update(done);
    }
    flush();
    splits[kSplits[sp]] = {{"count", counts[sp]}, {"shards", shards}, {"index", std::string(kSplits[sp]) + "-index.json"}};
    files.emplace_back(std::string(kSplits[sp]) + "-index.json", dump_json(index));
  }
  bar.finish();
  const world::GeneratorPreset preset = world::generator_preset(o.preset);
  Json doc = {{"format", kDatasetFormat},
              {"preset", o.preset},
              {"seed", o.seed},
              {"dims", {o.dims.x(), o.dims.y(), o.dims.z()}},
              {"bounds", {{"min", vec3_json(preset.bounds.min)}, {"max", vec3_json(preset.bounds.max)}}},
              {"channels", {"environment", "state", "target"}},
              {"environment_levels", {{"free", 0}, {"partial", 1}, {"solid", 2}}},
              {"dtype", "uint8"},
              {"layout", "sample, channel, z, y, x (x fastest)"},
              {"robot_radius", preset.robot_radius},
              {"dilation", o.dilation},
              {"min_separation", o.min_separation},
              {"map_seed_rule", "splitmix64(seed ^ k); train and val: k < count, test: k >= count"},
              {"splits", splits}};
  if (o.shard_count > 1) doc["part"] = {{"index", o.shard_index}, {"count", o.shard_count}};
  files.emplace_back("dataset.json", dump_json(doc));
  write_folder_atomic(dir, files);
  return doc;
}

Json merge_dataset_parts(const std::vector<std::string>& parts, const std::string& dir) {
  if (parts.empty()) throw Error("dataset merge: no part folders");
  std::vector<Json> docs;
  for (const auto& p : parts) {
    docs.push_back(read_json_file(p + "/dataset.json"));
    if (docs.back().value("format", "") != kDatasetFormat) throw Error(p + ": not a miner-dataset-v1 folder");
    if (!docs.back().contains("part")) throw Error(p + ": not a part folder (made without --shard)");
  }
  const auto common = [](Json d) {
    d.erase("part");
    for (auto& [name, split] : d["splits"].items()) split.erase("shards");
    return d;
  };
  const Json base = common(docs.front());
  std::vector<Json> tags;
  for (std::size_t p = 0; p < parts.size(); ++p) {
    if (common(docs[p]) != base) throw Error(parts[p] + ": a part of a different dataset (options differ)");
    tags.push_back(docs[p]["part"]);
  }
  require_complete_parts(tags, parts, "dataset merge: the dataset");
  Json doc = docs.front();
  doc.erase("part");
  std::vector<std::pair<std::string, std::string>> files;
  const JsonField dims_field(doc.at("dims"), "dims", parts.front() + "/dataset.json");
  const std::uint64_t cells = plan::HeuristicRegion::cell_count(
      Eigen::Vector3i(dims_field.at(std::size_t{0}).integer(), dims_field.at(std::size_t{1}).integer(),
                      dims_field.at(std::size_t{2}).integer()));
  for (const char* split : kSplits) {
    std::vector<std::pair<std::string, Json>> shards;  // file name -> shard record, from every part
    std::vector<Json> index;
    for (std::size_t p = 0; p < parts.size(); ++p) {
      const Json& sp = docs[p]["splits"][split];
      for (const auto& shard : sp["shards"]) {
        const std::string name = shard["file"].get<std::string>();
        shards.emplace_back(name, shard);
        std::string bytes = read_file_bytes(parts[p] + "/" + name, "dataset shard");
        // A truncated or padded shard is refused, not copied (issue 20): 3 grids per sample.
        const std::uint64_t expected = shard["count"].get<std::uint64_t>() * 3u * cells;
        if (bytes.size() != expected)
          throw Error(parts[p] + "/" + name + ": expected " + std::to_string(expected) + " bytes (" +
                      std::to_string(shard["count"].get<std::uint64_t>()) + " samples of 3 x " + std::to_string(cells) +
                      "), found " + std::to_string(bytes.size()));
        files.emplace_back(name, std::move(bytes));
      }
      for (const auto& e : read_json_file(parts[p] + "/" + sp["index"].get<std::string>())) index.push_back(e);
    }
    std::sort(shards.begin(), shards.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    std::sort(index.begin(), index.end(),
              [](const Json& a, const Json& b) { return a["k"].get<std::uint64_t>() < b["k"].get<std::uint64_t>(); });
    Json list = Json::array();
    for (const auto& s : shards) list.push_back(s.second);
    doc["splits"][split]["shards"] = list;
    std::uint64_t samples = 0;
    for (const auto& s : shards) samples += s.second["count"].get<std::uint64_t>();
    if (samples != doc["splits"][split]["count"].get<std::uint64_t>() || index.size() != samples)
      throw Error("dataset merge: split " + std::string(split) + " has " + std::to_string(samples) + " samples, expected " +
                  std::to_string(doc["splits"][split]["count"].get<std::uint64_t>()));
    files.emplace_back(std::string(split) + "-index.json", dump_json(Json(index)));
  }
  // Shard files in the unsharded run's order (split by split), then dataset.json.
  files.emplace_back("dataset.json", dump_json(doc));
  write_folder_atomic(dir, files);
  return doc;
}

std::vector<Sample> read_split(const std::string& dir, const std::string& split) {
  const Json doc = read_json_file(dir + "/dataset.json");
  const JsonField root(doc, "", dir + "/dataset.json");
  if (root.at("format").string() != kDatasetFormat) root.at("format").fail("not a miner-dataset-v1 folder");
  const JsonField dims_field = root.at("dims");
  const Eigen::Vector3i dims(dims_field.at(0).integer(), dims_field.at(1).integer(), dims_field.at(2).integer());
  const std::size_t cells = static_cast<std::size_t>(dims.prod());
  const JsonField sp = root.at("splits").at(split);
  const Json index = read_json_file(dir + "/" + sp.at("index").string());
  std::vector<Sample> out;
  for (std::size_t i = 0; i < sp.at("shards").array_size(); ++i) {
    const JsonField shard = sp.at("shards").at(i);
    const std::string path = dir + "/" + shard.at("file").string();
    const auto n = static_cast<std::size_t>(shard.at("count").integer());
    const std::string bytes = read_file_bytes(path, "the dataset shard");
    if (bytes.size() != n * 3 * cells)
      throw Error(path + ": expected " + std::to_string(n * 3 * cells) + " bytes (" + std::to_string(n) +
                  " samples of 3 x " + std::to_string(cells) + "), found " + std::to_string(bytes.size()));
    for (std::size_t s = 0; s < n; ++s) {
      Sample sample;
      const JsonField meta(index.at(out.size()), split + "-index[" + std::to_string(out.size()) + "]", dir);
      sample.map_seed = index.at(out.size()).at("map_seed").get<std::uint64_t>();
      sample.start = meta.at("start").vec3();
      sample.goal = meta.at("goal").vec3();
      sample.astar_cost = meta.at("astar_cost").number();
      const auto* base = reinterpret_cast<const std::uint8_t*>(bytes.data()) + s * 3 * cells;
      sample.environment.assign(base, base + cells);
      sample.state.assign(base + cells, base + 2 * cells);
      sample.target.assign(base + 2 * cells, base + 3 * cells);
      out.push_back(std::move(sample));
    }
  }
  return out;
}

}  // namespace miner::heuristic
