#include "miner/world/map.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>

#include <filesystem>
#include <fstream>

#include "miner/core/error.hpp"
#include "miner/core/json_io.hpp"
#include "miner/core/text.hpp"
#include "miner/core/sha256.hpp"
#include "miner/world/octree_io.hpp"
#include "miner/world/voxel_grid.hpp"

namespace miner::world {

namespace {

std::string axis_name(int k) { return std::string(1, "xyz"[k]); }

void validate_box(const Box& b, const std::string& what) {
  require_finite(b.min, what + ".min");
  require_finite(b.max, what + ".max");
  for (int k = 0; k < 3; ++k) {
    if (!(b.min[k] < b.max[k])) {
      std::ostringstream os;
      os << what << ": min[" << k << "] = " << b.min[k] << " must be less than max[" << k
         << "] = " << b.max[k] << " (" << axis_name(k) << " axis)";
      throw Error(os.str());
    }
  }
}


/// Below this many boxes a ray tests them all: the bucket walk costs more than it saves.
/// The comment line Map::save writes into the .bt beside a voxel map's JSON (after OctoMap's
/// header line, which readers require first): which program wrote the file.
constexpr const char* kSideFileMark = "# MINER Map::save:";
/// The voxel file's name carries this many hex digits of its SHA-256 (64 bits: two different
/// scans saved beside one JSON do not meet by chance).
constexpr std::size_t kSideFileHashDigits = 16;

constexpr std::size_t kRayWalkMinObstacles = 64;
/// At most this many pieces per ray (a diagonal of the 32-bucket grid is ~56 buckets long).
constexpr int kMaxRayPieces = 256;
/// A ray piece's bounding box is widened by this fraction of the map's extent, far above
/// the rounding of origin + t dir (~1e-16 relative) and far below a bucket (1/32).
constexpr double kRayPieceSlack = 1e-9;

std::string box_name(std::size_t i, const Box& b) {
  return "obstacle " + std::to_string(i) + " [" + format_point(b.min) + " - " +
         format_point(b.max) + "]";
}

}  // namespace

void check_resolution(double resolution, const std::string& field) {
  if (!std::isfinite(resolution) || resolution < kMinResolution || resolution > kMaxResolution) {
    std::ostringstream os;
    os << field << ": " << resolution << " m is outside the resolutions a map may have [" << kMinResolution << ", "
       << kMaxResolution << "] m";
    throw Error(os.str());
  }
}

void check_robot_radius(double radius, const std::string& field) {
  require_finite(radius, field);
  if (radius < 0.0 || radius > kMaxRobotRadius)
    throw Error(field + ": " + short_number(radius) + " m is outside [0, " + short_number(kMaxRobotRadius) + "] m");
}

Eigen::Vector3i grid_dims(const Box& bounds, double resolution) {
  // Tenth campaign L17: NaN bounds gave one cell.
  require_finite(bounds.min, "bounds.min");
  require_finite(bounds.max, "bounds.max");
  if (!(std::isfinite(resolution) && resolution > 0.0))
    throw Error("resolution: must be a positive finite length, got " + exact_number(resolution));
  // Snaps in the cell count: a face within this many cells of a whole number is on it.
  constexpr double kGridSnapTolerance = 1e-9;
  const Eigen::Vector3d extent = bounds.extent();
  // Compared in cells, with the snap: an extent of one cell that rounding left a hair short
  // (1.2 - 1.1 < 0.1 in doubles) is one cell (issue 20, sixth campaign: "0.1 m is coarser than
  // the smallest extent (0.1 m)").
  if (extent.minCoeff() / resolution < 1.0 - kGridSnapTolerance) {
    std::ostringstream os;
    os << "resolution: " << resolution << " m is coarser than the smallest extent of the bounds (" << extent.minCoeff()
       << " m): the grid would have no cell along that axis";
    throw Error(os.str());
  }
  Eigen::Vector3d cells;
  for (int k = 0; k < 3; ++k) cells[k] = std::max(1.0, std::ceil(extent[k] / resolution - kGridSnapTolerance));
  if (!(cells.prod() <= kMaxGridCells)) {
    std::ostringstream os;
    os << "resolution: " << resolution << " m gives a grid of " << cells.x() << " x " << cells.y() << " x "
       << cells.z() << " cells, more than the " << kMaxGridCells << " a map may have (A* keeps ~9 bytes per cell); "
       << "use a coarser resolution";
    throw Error(os.str());
  }
  return cells.cast<int>();
}

Map::Map(Box bounds, double resolution, std::vector<Box> obstacles, std::optional<Query> query,
         std::optional<VoxelSource> voxels)
    : bounds_(std::move(bounds)),
      resolution_(resolution),
      obstacles_(std::move(obstacles)),
      query_(std::move(query)),
      source_(std::move(voxels)) {
  validate_box(bounds_, "bounds");
  require_within_range(bounds_.min, "bounds.min", " (use a local frame)");
  require_within_range(bounds_.max, "bounds.max", " (use a local frame)");
  check_resolution(resolution_, "resolution");
  (void)grid_dims(bounds_, resolution_);  // a grid A* and the voxel grid can hold
  for (std::size_t i = 0; i < obstacles_.size(); ++i) {
    const std::string name = "obstacles[" + std::to_string(i) + "]";
    validate_box(obstacles_[i], name);
    // The metric range holds for obstacles too (issue 20, tenth campaign L9: a box of 1e300 m
    // was accepted and planned around).
    if (obstacles_[i].min.cwiseAbs().maxCoeff() > kMaxCoordinate || obstacles_[i].max.cwiseAbs().maxCoeff() > kMaxCoordinate) {
      std::ostringstream os;
      os << name << ": [" << format_point(obstacles_[i].min) << " - " << format_point(obstacles_[i].max)
         << "] reaches farther than " << kMaxCoordinate << " m from the origin (use a local frame)";
      throw Error(os.str());
    }
  }
  if (query_) {
    require_finite(query_->start, "query.start");
    require_finite(query_->goal, "query.goal");
    check_robot_radius(query_->robot_radius, "query.robot_radius");
    for (const auto& [p, name] : {std::pair{&query_->start, "query.start"}, std::pair{&query_->goal, "query.goal"}})
      if (!in_bounds(*p)) throw Error(std::string(name) + ": " + format_point(*p) + " lies outside the map bounds");
  }
  if (source_) {
    if (!source_->layer) throw Error("voxels: no layer");
    // Space inside the bounds but outside the voxels was never observed: it is unknown, and
    // the queries would answer it free. Under the default policy (unknown is occupied,
    // REQ-WORLD-013) such bounds are refused (issue 20, fourth campaign: a path through it;
    // tenth campaign L8: the constructor let it through where the JSON reader did not).
    if (source_->unknown == UnknownPolicy::kOccupied) {
      const Box lb = source_->layer->bounds();
      if ((bounds_.min.array() < lb.min.array()).any() || (bounds_.max.array() > lb.max.array()).any())
        throw Error("bounds: [" + format_point(bounds_.min) + " - " + format_point(bounds_.max) +
                    "] reaches beyond the voxels [" + format_point(lb.min) + " - " + format_point(lb.max) +
                    "]: the space outside them is unknown, which this map treats as occupied; keep the "
                    "bounds within the voxels or set \"voxels\": {\"unknown\": \"free\"}");
    }
    const VoxelLayer& layer = *source_->layer;
    // The map's grid and the voxels share cells: same resolution, bounds.min on the lattice.
    constexpr double kLatticeTolerance = 1e-9;
    if (std::abs(layer.resolution() - resolution_) > kLatticeTolerance * resolution_) {
      std::ostringstream os;
      os << "resolution: " << resolution_ << " m differs from the voxels' " << layer.resolution() << " m";
      throw Error(os.str());
    }
    for (int k = 0; k < 3; ++k) {
      const double cells = bounds_.min[k] / resolution_;
      if (std::abs(cells - std::round(cells)) > kLatticeTolerance * std::max(1.0, std::abs(cells))) {
        std::ostringstream os;
        os << "bounds.min[" << k << "] = " << bounds_.min[k] << " is not a multiple of the voxels' resolution "
           << resolution_ << " m (the map's grid must share the voxels' cells)";
        throw Error(os.str());
      }
    }
    voxels_ = std::make_shared<const VoxelObstacles>(source_->layer, source_->unknown);
  }
  build_index();
  // A stored query is one a planner can answer: both ends free at its radius (issue 20, tenth
  // campaign C1: a start inside a box passed `map info` and failed only in `astar` / `plan`).
  if (query_) {
    require_free(query_->start, query_->robot_radius, "query.start");
    require_free(query_->goal, query_->robot_radius, "query.goal");
  }
  compute_fingerprint();
}

void Map::compute_fingerprint() {
  std::uint64_t h = fnv1a64(bounds_.min.data(), 3 * sizeof(double));
  h = fnv1a64(bounds_.max.data(), 3 * sizeof(double), h);
  h = fnv1a64(&resolution_, sizeof resolution_, h);
  for (const Box& b : obstacles_) {
    h = fnv1a64(b.min.data(), 3 * sizeof(double), h);
    h = fnv1a64(b.max.data(), 3 * sizeof(double), h);
  }
  if (voxels_) {
    const VoxelLayer& layer = voxels_->layer();
    const std::uint8_t policy = source_->unknown == UnknownPolicy::kOccupied ? 1 : 0;
    h = fnv1a64(&policy, 1, h);
    h = fnv1a64(layer.origin_cells().data(), 3 * sizeof(int), h);
    h = fnv1a64(layer.dims().data(), 3 * sizeof(int), h);
    const double r = layer.resolution();
    h = fnv1a64(&r, sizeof r, h);
    h = fnv1a64(layer.states().data(), layer.states().size(), h);
  }
  fingerprint_.value = h == 0 ? 1 : h;  // 0 marks a moved-from map
}

Map Map::from_voxels(VoxelSource voxels) {
  if (!voxels.layer) throw Error("voxels: no layer");
  const VoxelLayer& layer = *voxels.layer;
  return Map(layer.bounds(), layer.resolution(), {}, std::nullopt, std::move(voxels));
}

Map Map::with_unknown(UnknownPolicy policy) const {
  if (!source_ || source_->unknown == policy) return *this;
  VoxelSource source = *source_;
  source.unknown = policy;
  return Map(bounds_, resolution_, obstacles_, query_, std::move(source));
}

namespace {

/// An obstacle index names a box or a voxel of this map (tenth campaign L3: an index of another
/// map read past the end).
void check_obstacle_index(std::size_t index, std::size_t boxes, const VoxelObstacles* voxels) {
  const std::size_t total = boxes + (voxels ? voxels->layer().size() : 0);
  if (index >= total)
    throw Error("obstacle index " + std::to_string(index) + ": the map has " + std::to_string(boxes) + " boxes" +
                (voxels ? " and " + std::to_string(voxels->layer().size()) + " voxels" : std::string()) +
                " (indices 0 to " + (total == 0 ? std::string("none") : std::to_string(total - 1)) + ")");
}

}  // namespace

Box Map::obstacle_box(std::size_t index) const {
  check_obstacle_index(index, obstacles_.size(), voxels_.get());
  if (index < obstacles_.size()) return obstacles_[index];
  return voxels_->layer().cell_box(voxels_->layer().coords(index - obstacles_.size()));
}

std::string Map::obstacle_name(std::size_t index) const {
  check_obstacle_index(index, obstacles_.size(), voxels_.get());
  if (index < obstacles_.size()) return box_name(index, obstacles_[index]);
  const VoxelLayer& layer = voxels_->layer();
  const std::size_t v = index - obstacles_.size();
  const Eigen::Vector3i c = layer.coords(v);
  const Box b = layer.cell_box(c);
  return std::string(layer.state(v) == VoxelState::kUnknown ? "unknown" : "occupied") + " voxel (" +
         std::to_string(c.x()) + ", " + std::to_string(c.y()) + ", " + std::to_string(c.z()) + ") [" +
         format_point(b.min) + " - " + format_point(b.max) + "]";
}

void Map::build_index() {
  // About 32^3 cubic buckets over the bounds: a few obstacles per bucket for the paper's maps;
  // fine enough that a short RRT edge visits few buckets. On a flat or thin map (a 1 km x 1 km
  // x 3 m forest) the buckets stay cubic and the budget goes to the long axes: an axis shorter
  // than a bucket gets one, and the others share the count (32 along the longest side only
  // left 31 m buckets there, each holding hundreds of trunks).
  constexpr double kBuckets = 32.0 * 32.0 * 32.0;
  index_.origin = bounds_.min;
  const Eigen::Vector3d extent = bounds_.extent();
  std::array<bool, 3> single{false, false, false};
  for (int pass = 0; pass < 3; ++pass) {
    double product = 1.0;
    int axes = 0;
    for (int k = 0; k < 3; ++k)
      if (!single[k]) product *= extent[k], ++axes;
    index_.cell = std::pow(product / kBuckets, 1.0 / axes);
    bool changed = false;
    for (int k = 0; k < 3; ++k)
      if (!single[k] && extent[k] < index_.cell && axes > 1) single[k] = changed = true;
    if (!changed) break;
  }
  for (int k = 0; k < 3; ++k) {
    index_.dims[k] = std::max(1, static_cast<int>(std::ceil(bounds_.extent()[k] / index_.cell)));
  }
  index_.buckets.assign(static_cast<std::size_t>(index_.dims.prod()), {});
  index_.large.clear();
  index_.beyond.clear();
  // A box over more buckets than this is listed once (index_.large): the index stays O(n).
  constexpr long kMaxBucketsPerObstacle = 512;
  for (std::size_t i = 0; i < obstacles_.size(); ++i) {
    if (!bounds_.contains(obstacles_[i].min) || !bounds_.contains(obstacles_[i].max)) index_.beyond.push_back(static_cast<std::uint32_t>(i));
    Eigen::Vector3i lo, hi;
    index_.span(obstacles_[i], lo, hi);
    if (static_cast<long>(hi.x() - lo.x() + 1) * (hi.y() - lo.y() + 1) * (hi.z() - lo.z() + 1) > kMaxBucketsPerObstacle) {
      index_.large.push_back(static_cast<std::uint32_t>(i));
      continue;
    }
    for (int z = lo.z(); z <= hi.z(); ++z)
      for (int y = lo.y(); y <= hi.y(); ++y)
        for (int x = lo.x(); x <= hi.x(); ++x) index_.buckets[index_.at(x, y, z)].push_back(static_cast<std::uint32_t>(i));
  }
}

void Map::BucketGrid::span(const Box& box, Eigen::Vector3i& lo, Eigen::Vector3i& hi) const {
  for (int k = 0; k < 3; ++k) {
    const auto coord = [&](double v) {
      const double c = std::floor((v - origin[k]) / cell);
      return static_cast<int>(std::min<double>(dims[k] - 1, std::max(0.0, c)));
    };
    lo[k] = coord(box.min[k]);
    hi[k] = coord(box.max[k]);
  }
}

template <typename Dist2>
std::optional<std::size_t> Map::query_index(const Box& region, double r2, const Dist2& dist2) const {
  Eigen::Vector3i lo, hi;
  index_.span(region, lo, hi);
  std::optional<std::size_t> best;
  const auto consider = [&](std::size_t i) {
    if ((!best || i < *best) && region.overlaps(obstacles_[i]) && dist2(obstacles_[i]) <= r2) best = i;
  };
  const long visits = static_cast<long>(hi.x() - lo.x() + 1) * (hi.y() - lo.y() + 1) * (hi.z() - lo.z() + 1);
  if (visits > static_cast<long>(obstacles_.size())) {  // a long query: a plain scan is cheaper
    for (std::size_t i = 0; i < obstacles_.size(); ++i) consider(i);
    return best;
  }
  for (const std::uint32_t i : index_.large) consider(i);
  for (int z = lo.z(); z <= hi.z(); ++z)
    for (int y = lo.y(); y <= hi.y(); ++y)
      for (int x = lo.x(); x <= hi.x(); ++x)
        for (const std::uint32_t i : index_.buckets[index_.at(x, y, z)]) consider(i);
  return best;
}

std::string Map::voxel_file_path(const std::string& map_path, const std::string& file) {
  namespace fs = std::filesystem;
  // An empty name is no file: the map's folder itself came back (tenth campaign recheck).
  if (file.empty()) throw Error(map_path + ": voxels.file: is empty: name the voxel file (.bt or .ot)");
  fs::path p = file;
  if (p.is_relative()) {
    // Relative to where the map file is: a map file reached through a link names its voxels
    // beside its target, where save() put them (seventeenth campaign F32).
    p = fs::path(link_target(map_path)).parent_path() / p;
  }
  return fs::absolute(p).lexically_normal().string();
}

Map Map::from_json(const Json& doc, const std::string& origin) {
  const JsonField root(doc, "", origin);
  root.require_format(kMapFormat);
  root.only_keys({"format", "bounds", "resolution", "obstacles", "query", "voxels"});
  std::optional<VoxelSource> voxels;
  if (root.has("voxels")) {
    const JsonField jv = root.at("voxels");
    jv.only_keys({"file", "sha256", "unknown"});
    // An empty name is named as such, and a hash must look like one before it is compared
    // (fifth campaign: "in/: not a regular file"; an upper-case or short hash called "the file
    // changed").
    if (jv.at("file").string().empty()) jv.at("file").fail("is empty: name the voxel file (.bt or .ot)");
    if (jv.has("sha256")) (void)sha256_field(jv.at("sha256"));
    const std::string file = voxel_file_path(origin, jv.at("file").string());
    VoxelSource source{nullptr, UnknownPolicy::kOccupied, file, {}};
    // The fault of a voxel file is named through the map that references it: "/dev/zero: not a
    // regular file" alone named neither (issue 20, sixth campaign U4).
    try {
      const std::string bytes = read_file_bytes(file, "voxel file");
      source.sha256 = sha256_hex(bytes);
      // What the file is comes first: a point cloud given as the voxel file was blamed on its
      // hash (issue 20, fourth campaign).
      source.layer = parse_octree(bytes, file);
    } catch (const Error& e) {
      jv.at("file").fail(e.what());
    }
    if (jv.has("sha256") && jv.at("sha256").string() != source.sha256) {
      jv.at("sha256").fail("the voxel file " + file + " has SHA-256 " + source.sha256 +
                           ", not the recorded one: the file changed since the map was written");
    }
    if (jv.has("unknown")) {
      try {
        source.unknown = parse_unknown_policy(jv.at("unknown").string(), "");  // the field names itself
      } catch (const Error& e) {
        jv.at("unknown").fail(e.what());
      }
    }
    voxels = std::move(source);
  }
  Box bounds = voxels ? voxels->layer->bounds() : Box{};
  double resolution = voxels ? voxels->layer->resolution() : 0.0;
  if (!voxels || root.has("bounds")) {
    const JsonField jb = root.at("bounds");
    jb.only_keys({"min", "max"});
    bounds = Box{jb.at("min").vec3(), jb.at("max").vec3()};
  }
  if (!voxels || root.has("resolution")) resolution = root.at("resolution").number();

  std::vector<Box> obstacles;
  const bool listed = !voxels || root.has("obstacles");  // a voxel map needs no box list
  const std::size_t n = listed ? root.at("obstacles").array_size() : 0;
  obstacles.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const JsonField jo = root.at("obstacles");
    const JsonField o = jo.at(i);
    o.only_keys({"type", "min", "max"});
    const std::string type = o.at("type").string();
    if (type != "box") o.at("type").fail("unknown obstacle type \"" + type + "\", expected \"box\"");
    obstacles.push_back({o.at("min").vec3(), o.at("max").vec3()});
  }

  std::optional<Query> query;
  if (root.has("query")) {
    const JsonField q = root.at("query");
    q.only_keys({"start", "goal", "robot_radius"});
    // The radius is required: a forgotten one planned for a point robot, touching obstacles
    // (issue 20); 0 must be said.
    // -0 reads as 0, as on the command line (eighteenth campaign F20: "robot radius -0 m").
    const auto plus_zero = [](Eigen::Vector3d v) { return Eigen::Vector3d(v.array() + 0.0); };
    query = Query{plus_zero(q.at("start").vec3()), plus_zero(q.at("goal").vec3()), q.at("robot_radius").number() + 0.0};
  }
  // Bounds reaching beyond the voxels under the occupied policy are refused by the constructor.
  try {
    Map map(bounds, resolution, std::move(obstacles), query, std::move(voxels));
    // A box farther from the bounds than the largest robot radius can meet no query: in a
    // file it is a mistake of units or frame, refused rather than ignored (issue 20, S6).
    const Box reach = map.bounds().inflated(kMaxRobotRadius);
    for (std::size_t i = 0; i < map.obstacles().size(); ++i)
      if (!reach.overlaps(map.obstacles()[i])) {
        std::ostringstream os;
        os << "obstacles[" << i << "] [" << format_point(map.obstacles()[i].min) << " - "
           << format_point(map.obstacles()[i].max) << "] lies more than " << kMaxRobotRadius
           << " m (the largest robot radius) outside the bounds [" << format_point(map.bounds().min) << " - "
           << format_point(map.bounds().max) << "], where no query can meet it: remove it or grow the bounds";
        throw Error(os.str());
      }
    return map;
  } catch (const Error& e) {
    throw Error(origin + ": " + e.what());
  }
}

Map Map::load(const std::string& path) {
  if (ends_with(path, ".bt") || ends_with(path, ".ot")) return load_octomap(path);
  require_path_without_nul(path, "file");
  require_json_file_size(path);
  const std::string bytes = read_file_bytes(path);
  // Formats MINER reads elsewhere, recognised by their first bytes, are named as such instead
  // of as malformed JSON (issue 20, fourth campaign: an OctoMap named .BT got the JSON
  // library's "invalid literal; last read: '#'").
  const auto starts_with = [&](const std::string& magic) { return bytes.compare(0, magic.size(), magic) == 0; };
  if (starts_with("# Octomap OcTree"))
    throw Error(path + ": is an OctoMap file, not a miner-map-v1 JSON: MINER reads OctoMaps by their suffix, .bt or "
                       ".ot (exactly, lower case); rename it");
  if (starts_with("ply\n") || starts_with("ply\r\n") || starts_with("# .PCD") || starts_with("VERSION"))
    throw Error(path + ": is a point cloud (PLY or PCD), not a map: turn it into one with `miner map import --cloud " +
                path + " --out map.bt`");
  return from_json(parse_json(bytes, path), path);
}

Json Map::to_json() const {
  Json obstacles = Json::array();
  for (const Box& b : obstacles_) {
    obstacles.push_back({{"type", "box"}, {"min", vec3_json(b.min)}, {"max", vec3_json(b.max)}});
  }
  Json doc = {{"format", kMapFormat},
              {"bounds", {{"min", vec3_json(bounds_.min)}, {"max", vec3_json(bounds_.max)}}},
              {"resolution", resolution_},
              {"obstacles", obstacles}};
  if (query_) {
    doc["query"] = {{"start", vec3_json(query_->start)},
                    {"goal", vec3_json(query_->goal)},
                    {"robot_radius", query_->robot_radius}};
  }
  if (source_) {
    if (source_->file.empty())
      throw Error("map: its voxels were made in memory and have no file to reference; save() it as JSON, which "
                  "writes them to a .bt beside it");
    doc["voxels"] = {{"file", source_->file}, {"sha256", source_->sha256}, {"unknown", to_string(source_->unknown)}};
  }
  return doc;
}

Map Map::load_octomap(const std::string& path) {
  namespace fs = std::filesystem;
  const std::string bytes = read_file_bytes(path, "OctoMap file");
  VoxelSource source{parse_octree(bytes, path), UnknownPolicy::kOccupied, fs::absolute(path).lexically_normal().string(),
                     sha256_hex(bytes)};
  try {
    return from_voxels(std::move(source));
  } catch (const Error& e) {
    // The map's checks name JSON fields ("bounds.min"); here the bounds are the voxels' (issue
    // 20, sixth campaign U2: a .bt far from the origin was refused naming no file).
    throw Error(path + ": the map its voxels span: " + e.what());
  }
}

VoxelLayer Map::to_voxel_layer() const {
  if (source_ && obstacles_.empty()) {
    const VoxelLayer& layer = *source_->layer;
    const Box lb = layer.bounds();
    if (lb.min == bounds_.min && lb.max == bounds_.max) return layer;
  }
  const VoxelGrid boxes(Map(bounds_, resolution_, obstacles_), 0.0);
  Eigen::Vector3i origin_cells;
  for (int k = 0; k < 3; ++k) origin_cells[k] = static_cast<int>(std::round(bounds_.min[k] / resolution_));
  std::vector<std::uint8_t> states(boxes.cell_count(), static_cast<std::uint8_t>(VoxelState::kFree));
  for (std::size_t i = 0; i < states.size(); ++i) {
    if (boxes.occupied(i)) {
      states[i] = static_cast<std::uint8_t>(VoxelState::kOccupied);
    } else if (source_) {
      const VoxelLayer& layer = *source_->layer;
      const Eigen::Vector3i c = boxes.coords(i) + origin_cells - layer.origin_cells();
      if ((c.array() >= 0).all() && (c.array() < layer.dims().array()).all())
        states[i] = layer.states()[layer.index(c.x(), c.y(), c.z())];
    }
  }
  return VoxelLayer(origin_cells, resolution_, boxes.dims(), std::move(states));
}

void Map::save_octomap(const std::string& path) const {
  // An OctoMap's voxels lie on multiples of the resolution from the origin: bounds off that
  // lattice would be written as the cells that cover them, and read back larger (issue 20,
  // fourth campaign: 4 m at 0.3 m came back as 4.2 m). Such a map is refused, not altered.
  constexpr double kLatticeTolerance = 1e-9;  // in cells: the bounds are written with %g-like decimals
  for (int k = 0; k < 3; ++k)
    for (const double edge : {bounds_.min[k], bounds_.max[k]}) {
      const double cells = edge / resolution_;
      if (std::fabs(cells - std::round(cells)) > kLatticeTolerance * std::max(1.0, std::fabs(cells))) {
        std::ostringstream os;
        // The fault is the map's, not the output's: "bounds" leads, the path it cannot go to
        // follows (sixth campaign U17: `map convert` blamed its output file).
        os << "bounds: " << format_point(bounds_.min) << " - " << format_point(bounds_.max)
           << " are not whole multiples of the resolution " << resolution_ << " m along " << "xyz"[k] << " (" << edge
           << " m is " << cells << " cells): an OctoMap's voxels lie on that lattice, so " << path
           << " would cover more than the map; use a resolution that divides the bounds, or write .json";
        throw Error(os.str());
      }
    }
  write_octree_bt(to_voxel_layer(), path);
}

std::string Map::voxel_side_file(const std::string& path, const std::string& sha256) {
  namespace fs = std::filesystem;
  // Beside the file the JSON really is: a JSON output that is a link is written into its target
  // (REQ-CORE-004), and its voxels go beside that target, so the map loads by either name
  // (seventeenth campaign F32: the .bt went beside the link and the target did not load).
  const fs::path json(link_target(path));
  return (json.parent_path() / (json.stem().string() + "." + sha256.substr(0, kSideFileHashDigits) + ".bt")).string();
}

void Map::save(const std::string& path) const {
  // issue 20: a ".ot" path got JSON that load() then read as an OctoMap and refused.
  if (path.size() >= 3 && path.compare(path.size() - 3, 3, ".ot") == 0)
    throw Error(path + ": MINER writes OctoMaps as .bt (binary occupancy) only, not .ot: name the output .bt or .json");
  // The name's suffix says what is written; a link is written through into its target, which
  // must carry the same suffix (REQ-CORE-004; nineteenth campaign F5: JSON went into a .bt).
  if (const std::string real = link_target(path);
      std::filesystem::path(real).extension() != std::filesystem::path(path).extension())
    throw Error(path + ": a symbolic link to " + real + ", whose suffix is not the link's: the file written there would " +
                "hold what " + path + " asks for under another kind's name (give the target's own name)");
  if (ends_with(path, ".bt")) {
    save_octomap(path);
  } else if (source_ && source_->file.empty()) {
    // The voxels first, then the document that names them: a reader never sees a reference to a
    // file that is not there yet. The voxel file is named by its content and never replaced:
    // other map files and run folders reference it by SHA-256, and a later save with other
    // voxels writes another file beside it (seventeenth campaign F9: re-generating a scan
    // replaced s.bt and every map file that named it stopped loading). The mark line (after
    // OctoMap's first line) says which save wrote it.
    std::string bytes = octree_bt_bytes(*source_->layer);
    bytes.insert(bytes.find('\n') + 1, std::string(kSideFileMark) + " the map JSON beside it\n");
    const std::string sha = sha256_hex(bytes);
    const std::filesystem::path bt = voxel_side_file(path, sha);
    std::error_code ec;
    if (std::filesystem::exists(bt, ec)) {
      // The same name is the same content unless a user put a file there: that one is kept.
      std::string existing;
      try {
        existing = read_file_bytes(bt.string());
      } catch (const Error&) {
        existing.clear();
      }
      if (existing != bytes)
        throw Error(bt.string() + ": exists with other content than the voxels of the map saved to " + path +
                    " (the name is their SHA-256's first " + std::to_string(kSideFileHashDigits) +
                    " digits): it is not replaced (remove it, or choose another output name)");
    } else {
      write_file_atomic(bt.string(), bytes);
    }
    VoxelSource saved = *source_;
    saved.file = std::filesystem::absolute(bt).lexically_normal().string();
    saved.sha256 = sha;
    Json doc = Map(bounds_, resolution_, obstacles_, query_, std::move(saved)).to_json();
    doc["voxels"]["file"] = bt.filename().string();  // relative: the pair moves together
    write_file_atomic(path, dump_json(doc, path));
  } else {
    // A voxel map read from a file is written as a reference to it: the file must still hold the
    // voxels, or the JSON would name what is gone (eighteenth campaign F21: the .bt was deleted
    // after loading, and the saved JSON could not be loaded).
    if (source_ && !source_->file.empty()) {
      std::string bytes;
      try {
        bytes = read_file_bytes(source_->file);
      } catch (const Error&) {
        throw Error(path + ": voxels.file: " + source_->file +
                    " cannot be read any more, and the map's JSON would reference it: save as .bt to write the "
                    "voxels themselves");
      }
      if (sha256_hex(bytes) != source_->sha256)
        throw Error(path + ": voxels.file: " + source_->file + " changed since the map was read (SHA-256 " +
                    sha256_hex(bytes) + ", not " + source_->sha256 +
                    "), and the map's JSON would reference it: save as .bt to write the voxels themselves");
    }
    write_file_atomic(path, dump_json(to_json(), path));
  }
}

std::optional<std::size_t> Map::point_collision(const Eigen::Vector3d& p, double radius) const {
  check_query_point(p, "point_collision: p");
  check_query_radius(radius, "point_collision: radius");
  const Box region{p.array() - radius, p.array() + radius};
  if (auto hit = query_index(region, radius * radius, [&](const Box& b) { return squared_distance(p, b); }))
    return hit;
  if (voxels_) {
    if (const auto v = voxels_->point_hit(p, radius)) return obstacles_.size() + *v;
  }
  return std::nullopt;
}

std::optional<std::size_t> Map::segment_collision(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                                  double radius) const {
  check_query_point(a, "segment_collision: a");
  check_query_point(b, "segment_collision: b");
  check_query_radius(radius, "segment_collision: radius");
  const Box sweep{a.cwiseMin(b).array() - radius, a.cwiseMax(b).array() + radius};
  if (auto hit = query_index(sweep, radius * radius, [&](const Box& box) { return squared_distance(a, b, box); }))
    return hit;
  if (voxels_) {
    if (const auto v = voxels_->segment_hit(a, b, radius)) return obstacles_.size() + *v;
  }
  return std::nullopt;
}

double Map::clearance(const Eigen::Vector3d& p) const {
  check_query_point(p, "clearance: p");
  require_within_range(p, "clearance: p", " (a map's range): no distance is asked that far");
  double best = std::numeric_limits<double>::infinity();
  for (const Box& b : obstacles_) best = std::min(best, squared_distance(p, b));
  best = std::sqrt(best);
  return voxels_ ? std::min(best, voxels_->clearance(p)) : best;
}

std::optional<double> Map::raycast(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double max_range) const {
  check_query_point(origin, "raycast: origin");
  check_query_direction(dir, "raycast: dir");
  check_query_radius(max_range, "raycast: max_range");
  std::optional<double> best = voxels_ ? voxels_->raycast(origin, dir, max_range) : std::nullopt;
  const auto consider = [&](std::size_t i) {
    if (const auto t = ray_interval(obstacles_[i], origin, dir, best ? *best : max_range)) best = t->first;
  };
  const auto brute_force = [&] {
    for (std::size_t i = 0; i < obstacles_.size(); ++i) consider(i);
    return best;
  };
  // The ray's stretch inside the bounds, where every obstacle contained in the bounds is met
  // (a box inside the bounds is entered inside them; the slab arithmetic is monotone, so the
  // computed entry of such a box is never before the computed entry of the bounds).
  if (dir.isZero() || !std::isfinite(max_range) || obstacles_.size() < kRayWalkMinObstacles) return brute_force();
  for (const std::uint32_t i : index_.large) consider(i);
  for (const std::uint32_t i : index_.beyond) consider(i);
  const auto inside = ray_interval(bounds_, origin, dir, max_range);
  if (!inside) return best;
  const auto [t_in, t_out] = *inside;
  // Walk the stretch in pieces about one bucket long, nearest first. Each piece's bounding
  // box (widened by kRayPieceSlack against rounding of the end points) selects buckets with
  // the same span() the index was built with, so a box containing a point of the piece is in
  // one of them; once a piece starts beyond the best hit no later piece can improve it.
  const double norm = dir.norm();
  const double length = (t_out - t_in) * norm;
  const int pieces = static_cast<int>(std::min<double>(kMaxRayPieces, std::ceil(length / index_.cell) + 1.0));
  const double slack = kRayPieceSlack * bounds_.extent().maxCoeff();
  for (int p = 0; p < pieces; ++p) {
    const double ta = t_in + (t_out - t_in) * p / pieces;
    const double tb = p + 1 == pieces ? t_out : t_in + (t_out - t_in) * (p + 1) / pieces;
    if (best && ta > *best) break;
    const Eigen::Vector3d a = origin + ta * dir, b = origin + tb * dir;
    const Box piece = Box{a.cwiseMin(b), a.cwiseMax(b)}.inflated(slack);
    Eigen::Vector3i lo, hi;
    index_.span(piece, lo, hi);
    for (int z = lo.z(); z <= hi.z(); ++z)
      for (int y = lo.y(); y <= hi.y(); ++y)
        for (int x = lo.x(); x <= hi.x(); ++x)
          for (const std::uint32_t i : index_.buckets[index_.at(x, y, z)]) consider(i);
  }
  return best;
}

void Map::require_free(const Eigen::Vector3d& p, double radius, const std::string& what) const {
  require_finite(p, what);
  check_robot_radius(radius, what + ": robot radius");
  if (!in_bounds(p)) {
    throw Error(what + " " + format_point(p) + " lies outside the map bounds [" +
                format_point(bounds_.min) + " - " + format_point(bounds_.max) + "]");
  }
  if (const auto hit = point_collision(p, radius)) {
    const Box b = obstacle_box(*hit);
    std::ostringstream os;
    if (squared_distance(p, b) == 0.0) {
      os << what << " " << format_point(p) << " lies inside " << obstacle_name(*hit);
    } else {
      os << what << " " << format_point(p) << " is within the robot radius " << radius << " of "
         << obstacle_name(*hit) << " (clearance " << std::sqrt(squared_distance(p, b)) << ")";
    }
    throw Error(os.str());
  }
}

}  // namespace miner::world
