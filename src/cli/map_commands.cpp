// `miner map gen|info|convert` and `miner astar` (REQ-CLI-*, REQ-WORLD-*).
#include <cmath>
#include <iomanip>
#include <memory>
#include <optional>
#include <ostream>
#include <sstream>

#include <CLI/CLI.hpp>

#include "cli/cli.hpp"
#include "miner/core/error.hpp"
#include "miner/core/json_io.hpp"
#include "miner/world/astar.hpp"
#include "miner/world/map.hpp"
#include "miner/world/map_generator.hpp"
#include "miner/world/voxel_grid.hpp"

namespace miner::cli {

namespace {

using world::Map;

struct GenOptions {
  std::string preset = "sim";
  std::uint64_t seed = 1;
  int obstacles = -1;
  std::vector<double> size;
  double resolution = 0.0;
  std::string out;
};

void run_gen(const GenOptions& o, std::ostream& out) {
  const auto preset = world::generator_preset(o.preset);
  world::GeneratorOverrides overrides;
  if (o.obstacles >= 0) overrides.obstacles = o.obstacles;
  if (!o.size.empty()) overrides.size = Eigen::Vector3d(o.size[0], o.size[1], o.size[2]);
  if (o.resolution != 0.0) overrides.resolution = o.resolution;
  const Map map = world::generate_map(preset, o.seed, overrides);
  map.save(o.out);
  const Eigen::Vector3d e = map.bounds().extent();
  out << "wrote " << o.out << ": preset " << o.preset << ", seed " << o.seed << ", " << e.x() << " x " << e.y()
      << " x " << e.z() << " m at " << map.resolution() << " m, " << map.obstacles().size() << " obstacles\n";
}

struct InfoOptions {
  std::string map;
  std::string unknown;
  double radius = -1.0;
  OutputOptions output;
};

void run_info(const InfoOptions& o, std::ostream& out) {
  const Map map = load_map(o.map, o.unknown);
  const double radius = o.radius >= 0.0 ? o.radius : (map.query() ? map.query()->robot_radius : 0.0);
  const world::VoxelGrid grid(map, radius);
  const double occupied = static_cast<double>(grid.occupied_count()) / static_cast<double>(grid.cell_count());
  Json doc = {{"map", o.map},
              {"bounds", {{"min", vec3_json(map.bounds().min)}, {"max", vec3_json(map.bounds().max)}}},
              {"resolution", map.resolution()},
              {"obstacles", map.obstacles().size()},
              {"grid", {{"dims", {grid.dims().x(), grid.dims().y(), grid.dims().z()}},
                        {"cells", grid.cell_count()},
                        {"robot_radius", radius},
                        {"occupied_cells", grid.occupied_count()},
                        {"occupied_fraction", occupied}}}};
  if (map.query()) {
    doc["query"] = {{"start", vec3_json(map.query()->start)},
                    {"goal", vec3_json(map.query()->goal)},
                    {"robot_radius", map.query()->robot_radius}};
  }
  std::ostringstream h;
  h << "map:         " << o.map << "\n"
    << "bounds:      " << format_point(map.bounds().min) << " - " << format_point(map.bounds().max) << " m\n"
    << "resolution:  " << map.resolution() << " m\n"
    << "obstacles:   " << map.obstacles().size() << " boxes\n";
  if (const world::VoxelObstacles* v = map.voxels()) {
    const world::VoxelLayer& layer = v->layer();
    const double cell = std::pow(layer.resolution(), 3);
    Json counts = Json::object();
    h << "voxels:      " << layer.dims().x() << " x " << layer.dims().y() << " x " << layer.dims().z() << " from "
      << map.voxel_source()->file << "\n";
    for (const auto state : {world::VoxelState::kFree, world::VoxelState::kOccupied, world::VoxelState::kUnknown}) {
      const char* name = state == world::VoxelState::kFree ? "free" : state == world::VoxelState::kOccupied ? "occupied" : "unknown";
      const std::size_t n = layer.count(state);
      counts[name] = {{"voxels", n}, {"volume_m3", static_cast<double>(n) * cell}};
      h << "  " << std::left << std::setw(10) << name << std::right << n << " voxels, " << static_cast<double>(n) * cell
        << " m^3\n";
    }
    h << "unknown:     treated as " << world::to_string(v->policy())
      << (v->policy() == world::UnknownPolicy::kOccupied ? " (the safe default; --unknown free to fly through it)"
                                                         : " (on request)")
      << "\n";
    doc["voxels"] = {{"file", map.voxel_source()->file},
                     {"sha256", map.voxel_source()->sha256},
                     {"dims", {layer.dims().x(), layer.dims().y(), layer.dims().z()}},
                     {"counts", counts},
                     {"unknown_policy", world::to_string(v->policy())}};
  }
  h
    << "grid:        " << grid.dims().x() << " x " << grid.dims().y() << " x " << grid.dims().z()
    << " = " << grid.cell_count() << " cells, " << std::fixed << std::setprecision(1)
    << 100.0 * occupied << " % occupied for robot radius " << std::defaultfloat << radius << " m\n";
  if (map.query()) {
    h << "query:       start " << format_point(map.query()->start) << ", goal "
      << format_point(map.query()->goal) << ", robot radius " << map.query()->robot_radius << " m\n";
  }
  emit(o.output, doc, h.str(), out);
}

struct ConvertOptions {
  std::string in, out;
};

void run_convert(const ConvertOptions& o, std::ostream& out) {
  const Map map = Map::load(o.in);
  map.save(o.out);
  out << "wrote " << o.out << " (" << map.obstacles().size() << " obstacles";
  if (map.voxels()) out << ", " << map.voxels()->layer().count(world::VoxelState::kOccupied) << " occupied voxels";
  out << " from " << o.in << ")\n";
}

struct AstarOptions {
  QueryOptions query;
  OutputOptions output;
};

void run_astar(const AstarOptions& o, std::ostream& out) {
  const ResolvedQuery q = resolve_query(o.query);
  const Map& map = q.map;
  const Eigen::Vector3d& start = q.start;
  const Eigen::Vector3d& goal = q.goal;
  const double radius = q.radius;
  const world::VoxelGrid grid(map, radius);
  const world::GridPath path = world::astar(map, grid, start, goal);

  Json points = Json::array();
  for (const auto& p : path.points) points.push_back(vec3_json(p));
  const Json doc = {{"map", o.query.map},
                    {"start", vec3_json(start)},
                    {"goal", vec3_json(goal)},
                    {"robot_radius", radius},
                    {"resolution", grid.resolution()},
                    {"cost", path.cost},
                    {"grid_cost", path.grid_cost},
                    {"expanded", path.expanded},
                    {"points", points}};
  std::ostringstream h;
  h << "A* on " << grid.dims().x() << " x " << grid.dims().y() << " x " << grid.dims().z()
    << " grid (" << grid.resolution() << " m, robot radius " << radius << " m)\n"
    << "start " << format_point(start) << " -> goal " << format_point(goal) << "\n"
    << "path: " << path.points.size() << " points, cost " << std::fixed << std::setprecision(3)
    << path.cost << " m (straight line " << (goal - start).norm() << " m), " << path.expanded
    << " cells expanded\n";
  emit(o.output, doc, h.str(), out);
}

}  // namespace

void add_map_commands(CLI::App& app, std::ostream& out) {
  CLI::App* map = app.add_subcommand("map", "generate, inspect and convert maps");
  map->require_subcommand(1);

  auto gen = std::make_shared<GenOptions>();
  CLI::App* g = map->add_subcommand("gen", "generate a seeded map (presets: sim, indoor, cluttered, rooms, forest, multilevel)");
  g->add_option("--preset", gen->preset,
                "map preset: sim (100 m, paper Sec. V-B), indoor (10 m site, Sec. V-D), or a family drawing its "
                "size per map: cluttered, rooms, forest, multilevel")
      ->capture_default_str();
  g->add_option("--seed", gen->seed, "random seed")->capture_default_str()->check(kUnsigned64);
  g->add_option("--obstacles", gen->obstacles, "number of obstacles (default: the preset's range)")
      ->check(kFiniteNonNegative);
  g->add_option("--size", gen->size, "families: extents X Y Z in m instead of drawn ones")->expected(3);
  g->add_option("--resolution", gen->resolution, "families: grid resolution in m instead of the drawn one");
  g->add_option("--out", gen->out, "output file (.json, or .bt for OctoMap)")->required()->check(kOutputFile);
  g->callback([gen, &out] { run_gen(*gen, out); });

  auto info = std::make_shared<InfoOptions>();
  CLI::App* i = map->add_subcommand("info", "summarise a map and its occupancy grid");
  i->add_option("--map", info->map, "map file (.json, or an OctoMap .bt/.ot)")->required();
  i->add_option("--unknown", info->unknown, "voxel maps: count unknown space as 'occupied' or 'free' in the grid")
      ->check(CLI::IsMember({"occupied", "free"}));
  i->add_option("--radius", info->radius, "robot radius in m (default: the map's query radius or 0)")
      ->check(kFiniteNonNegative);
  add_output_options(i, info->output);
  i->callback([info, &out] { run_info(*info, out); });

  auto conv = std::make_shared<ConvertOptions>();
  CLI::App* c = map->add_subcommand("convert", "convert between miner-map-v1 JSON and OctoMap .bt (a voxel map's JSON references its .bt by path and SHA-256)");
  c->add_option("--in", conv->in, "input map (.json, .bt or .ot)")->required();
  c->add_option("--out", conv->out, "output map (.json or .bt)")->required()->check(kOutputFile);
  c->callback([conv, &out] { run_convert(*conv, out); });

  auto astar = std::make_shared<AstarOptions>();
  CLI::App* a = app.add_subcommand("astar", "shortest 26-connected grid path (A*) between two points");
  add_query_options(a, astar->query);
  add_output_options(a, astar->output);
  a->callback([astar, &out] { run_astar(*astar, out); });
}

}  // namespace miner::cli
