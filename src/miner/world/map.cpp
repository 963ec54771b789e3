#include "miner/world/map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "miner/core/error.hpp"

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


std::string obstacle_name(std::size_t i, const Box& b) {
  return "obstacle " + std::to_string(i) + " [" + format_point(b.min) + " - " +
         format_point(b.max) + "]";
}

}  // namespace

Eigen::Vector3i grid_dims(const Box& bounds, double resolution) {
  // Snaps in the cell count: a face within this many cells of a whole number is on it.
  constexpr double kGridSnapTolerance = 1e-9;
  const Eigen::Vector3d extent = bounds.extent();
  if (resolution > extent.minCoeff()) {
    std::ostringstream os;
    os << "resolution: " << resolution << " m is coarser than the smallest extent of the bounds ("
       << extent.minCoeff() << " m): the grid would have no cell along that axis";
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

Map::Map(Box bounds, double resolution, std::vector<Box> obstacles, std::optional<Query> query)
    : bounds_(std::move(bounds)),
      resolution_(resolution),
      obstacles_(std::move(obstacles)),
      query_(std::move(query)) {
  validate_box(bounds_, "bounds");
  require_finite(resolution_, "resolution");
  if (!(resolution_ > 0.0)) {
    std::ostringstream os;
    os << "resolution: must be positive, got " << resolution_;
    throw Error(os.str());
  }
  (void)grid_dims(bounds_, resolution_);  // a grid A* and the voxel grid can hold
  for (std::size_t i = 0; i < obstacles_.size(); ++i) {
    validate_box(obstacles_[i], "obstacles[" + std::to_string(i) + "]");
  }
  if (query_) {
    require_finite(query_->start, "query.start");
    require_finite(query_->goal, "query.goal");
    require_finite(query_->robot_radius, "query.robot_radius");
    if (query_->robot_radius < 0.0) throw Error("query.robot_radius: must not be negative");
  }
  build_index();
}

void Map::build_index() {
  // About 32 buckets along the longest side: a few obstacles per bucket for the paper's
  // maps; fine enough that a short RRT edge visits few buckets.
  constexpr int kBucketsPerSide = 32;
  index_.origin = bounds_.min;
  index_.cell = bounds_.extent().maxCoeff() / kBucketsPerSide;
  for (int k = 0; k < 3; ++k) {
    index_.dims[k] = std::max(1, static_cast<int>(std::ceil(bounds_.extent()[k] / index_.cell)));
  }
  index_.buckets.assign(static_cast<std::size_t>(index_.dims.prod()), {});
  for (std::size_t i = 0; i < obstacles_.size(); ++i) {
    Eigen::Vector3i lo, hi;
    index_.span(obstacles_[i], lo, hi);
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
  for (int z = lo.z(); z <= hi.z(); ++z)
    for (int y = lo.y(); y <= hi.y(); ++y)
      for (int x = lo.x(); x <= hi.x(); ++x)
        for (const std::uint32_t i : index_.buckets[index_.at(x, y, z)]) consider(i);
  return best;
}

Map Map::from_json(const Json& doc, const std::string& origin) {
  const JsonField root(doc, "", origin);
  if (!doc.is_object()) root.fail("expected a JSON object with \"format\": \"miner-map-v1\"");
  const std::string format = root.at("format").string();
  if (format != kMapFormat) {
    root.at("format").fail("unknown format tag \"" + format + "\", expected \"" + kMapFormat + "\"");
  }
  root.only_keys({"format", "bounds", "resolution", "obstacles", "query"});
  const JsonField jb = root.at("bounds");
  jb.only_keys({"min", "max"});
  Box bounds{jb.at("min").vec3(), jb.at("max").vec3()};
  const double resolution = root.at("resolution").number();

  std::vector<Box> obstacles;
  const JsonField jo = root.at("obstacles");
  const std::size_t n = jo.array_size();
  obstacles.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
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
    query = Query{q.at("start").vec3(), q.at("goal").vec3(),
                  q.has("robot_radius") ? q.at("robot_radius").number() : 0.0};
  }
  try {
    return Map(bounds, resolution, std::move(obstacles), query);
  } catch (const Error& e) {
    throw Error(origin + ": " + e.what());
  }
}

Map Map::load(const std::string& path) {
  const auto ends_with = [&](const std::string& suffix) {
    return path.size() >= suffix.size() &&
           path.compare(path.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  if (ends_with(".bt")) return load_octomap(path);
  return from_json(read_json_file(path), path);
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
  return doc;
}

void Map::save(const std::string& path) const {
  if (path.size() >= 3 && path.compare(path.size() - 3, 3, ".bt") == 0) {
    save_octomap(path);
  } else {
    write_file_atomic(path, dump_json(to_json()));
  }
}

std::optional<std::size_t> Map::point_collision(const Eigen::Vector3d& p, double radius) const {
  const Box region{p.array() - radius, p.array() + radius};
  return query_index(region, radius * radius, [&](const Box& b) { return squared_distance(p, b); });
}

std::optional<std::size_t> Map::segment_collision(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                                  double radius) const {
  const Box sweep{a.cwiseMin(b).array() - radius, a.cwiseMax(b).array() + radius};
  return query_index(sweep, radius * radius, [&](const Box& box) { return squared_distance(a, b, box); });
}

double Map::clearance(const Eigen::Vector3d& p) const {
  double best = std::numeric_limits<double>::infinity();
  for (const Box& b : obstacles_) best = std::min(best, squared_distance(p, b));
  return std::sqrt(best);
}

void Map::require_free(const Eigen::Vector3d& p, double radius, const std::string& what) const {
  require_finite(p, what);
  if (!in_bounds(p)) {
    throw Error(what + " " + format_point(p) + " lies outside the map bounds [" +
                format_point(bounds_.min) + " - " + format_point(bounds_.max) + "]");
  }
  if (const auto hit = point_collision(p, radius)) {
    const Box& b = obstacles_[*hit];
    std::ostringstream os;
    if (squared_distance(p, b) == 0.0) {
      os << what << " " << format_point(p) << " lies inside " << obstacle_name(*hit, b);
    } else {
      os << what << " " << format_point(p) << " is within the robot radius " << radius << " of "
         << obstacle_name(*hit, b) << " (clearance " << std::sqrt(squared_distance(p, b)) << ")";
    }
    throw Error(os.str());
  }
}

}  // namespace miner::world
