#include "bench/voxel_bench.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

#include "miner/core/error.hpp"
#include "miner/core/rng.hpp"
#include "miner/core/stopwatch.hpp"
#include "miner/heuristic/grid.hpp"
#include "miner/plan/heuristic_region.hpp"
#include "miner/world/map.hpp"
#include "miner/world/voxel_grid.hpp"

namespace miner::bench {

namespace {

using Clock = std::chrono::steady_clock;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

Eigen::Vector3d uniform_point(Rng& rng, const world::Box& b) {
  return {rng.uniform(b.min.x(), b.max.x()), rng.uniform(b.min.y(), b.max.y()), rng.uniform(b.min.z(), b.max.z())};
}

Eigen::Vector3d unit_vector(Rng& rng) {
  const Eigen::Vector3d v(rng.normal(), rng.normal(), rng.normal());
  return v.norm() > 0.0 ? Eigen::Vector3d(v.normalized()) : Eigen::Vector3d::UnitX();
}

}  // namespace

Json run_voxel_bench(const std::string& path, const VoxelBenchOptions& o) {
  if (o.repeats < 1 || o.queries < 1) throw Error("bench voxels: --repeats and --queries must be at least 1");
  std::vector<double> load_ms;
  std::optional<world::Map> map;
  for (int i = 0; i < o.repeats; ++i) {
    const auto t0 = Clock::now();
    map.emplace(world::Map::load(path));
    load_ms.push_back(elapsed_ms(t0));
  }
  Json doc = {{"map", path}, {"robot_radius", o.robot_radius}, {"queries", o.queries}, {"repeats", o.repeats},
              {"load_ms", median(load_ms)}, {"load_ms_max", *std::max_element(load_ms.begin(), load_ms.end())}};
  if (const world::VoxelObstacles* v = map->voxels()) {
    const world::VoxelLayer& layer = v->layer();
    doc["voxels"] = {{"dims", {layer.dims().x(), layer.dims().y(), layer.dims().z()}},
                     {"count", layer.size()},
                     {"occupied", layer.count(world::VoxelState::kOccupied)},
                     {"unknown", layer.count(world::VoxelState::kUnknown)},
                     {"layer_bytes", layer.size()},
                     {"field_bytes", v->field_bytes()}};
  }
  // Random queries over the bounds, drawn before timing so only the queries are timed.
  Rng rng(o.seed);
  const world::Box& b = map->bounds();
  std::vector<Eigen::Vector3d> a(o.queries), d(o.queries);
  for (std::size_t i = 0; i < o.queries; ++i) {
    a[i] = uniform_point(rng, b);
    d[i] = unit_vector(rng);
  }
  const auto rate = [&](auto&& query) {
    std::size_t positive = 0;
    const auto t0 = Clock::now();
    for (std::size_t i = 0; i < o.queries; ++i) positive += query(i) ? 1 : 0;
    const double ms = elapsed_ms(t0);
    return Json{{"per_second", static_cast<double>(o.queries) / (ms / 1000.0)}, {"hits", positive}};
  };
  doc["point"] = rate([&](std::size_t i) { return map->point_collision(a[i], o.robot_radius).has_value(); });
  doc["segment"] = rate([&](std::size_t i) {
    return map->segment_collision(a[i], a[i] + o.segment_length * d[i], o.robot_radius).has_value();
  });
  doc["ray"] = rate([&](std::size_t i) { return map->raycast(a[i], d[i], o.ray_range).has_value(); });
  std::vector<double> grid_ms, encode_ms;
  for (int i = 0; i < o.repeats; ++i) {
    auto t0 = Clock::now();
    const world::VoxelGrid grid(*map, o.robot_radius);
    grid_ms.push_back(elapsed_ms(t0));
    t0 = Clock::now();
    const auto e = heuristic::encode_environment(*map, plan::HeuristicRegion::default_dims(), o.robot_radius);
    encode_ms.push_back(elapsed_ms(t0));
  }
  doc["astar_grid_ms"] = median(grid_ms);
  doc["encode_ms"] = median(encode_ms);
  doc["encode_ms_max"] = *std::max_element(encode_ms.begin(), encode_ms.end());
  return doc;
}

void print_voxel_bench(const Json& doc, std::ostream& out) {
  char line[256];
  out << "map " << doc["map"].get<std::string>() << "\n";
  if (doc.contains("voxels")) {
    const Json& v = doc["voxels"];
    std::snprintf(line, sizeof line, "voxels %d x %d x %d = %.0f (%.0f occupied, %.0f unknown); memory %.1f MB (layer) + %.1f MB (distance field)\n",
                  v["dims"][0].get<int>(), v["dims"][1].get<int>(), v["dims"][2].get<int>(), v["count"].get<double>(),
                  v["occupied"].get<double>(), v["unknown"].get<double>(), v["layer_bytes"].get<double>() / 1e6,
                  v["field_bytes"].get<double>() / 1e6);
    out << line;
  }
  std::snprintf(line, sizeof line, "load %.1f ms (median of %d, max %.1f)\n", doc["load_ms"].get<double>(),
                doc["repeats"].get<int>(), doc["load_ms_max"].get<double>());
  out << line;
  for (const char* kind : {"point", "segment", "ray"}) {
    std::snprintf(line, sizeof line, "%-8s %12.0f queries/s (%.0f of %.0f hit)\n", kind,
                  doc[kind]["per_second"].get<double>(), doc[kind]["hits"].get<double>(), doc["queries"].get<double>());
    out << line;
  }
  std::snprintf(line, sizeof line, "A* grid %.1f ms, sGAN channel E %.2f ms (median; max %.2f), robot radius %g m\n",
                doc["astar_grid_ms"].get<double>(), doc["encode_ms"].get<double>(), doc["encode_ms_max"].get<double>(),
                doc["robot_radius"].get<double>());
  out << line;
}

}  // namespace miner::bench
