#pragma once
/// \file
/// The world model: a bounded 3D workspace with box obstacles (paper Sec. III-A:
/// X = bounds, X_obs = union of boxes, X_free = closure(X \ X_obs)).
///
/// File format `miner-map-v1` (REQ-WORLD-001), ENU metres, z up:
///   {"format": "miner-map-v1",
///    "bounds": {"min": [0,0,0], "max": [100,100,100]},
///    "resolution": 0.5,
///    "obstacles": [{"type": "box", "min": [10,10,0], "max": [20,25,40]}],
///    "query": {"start": [..], "goal": [..], "robot_radius": 0.5},    // optional
///    "voxels": {"file": "scan.bt", "sha256": "..", "unknown": "occupied"}}  // optional
/// OctoMap files (`.bt`, `.ot`) load as voxel maps (REQ-WORLD-003, REQ-WORLD-012): free, occupied
/// and unknown voxels with their exact leaf geometry. A JSON map may reference such a file
/// ("file" relative to the JSON's folder, its SHA-256 checked when given; REQ-WORLD-015), and
/// then "bounds" and "resolution" default to the voxels'; boxes and voxels obstruct together.
/// The unknown-space policy (REQ-WORLD-013) is "occupied" unless the map or the query says
/// "free"; collision queries see blocked voxels through world::VoxelObstacles.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "miner/core/json_io.hpp"
#include "miner/core/units.hpp"
#include "miner/world/box.hpp"
#include "miner/world/voxel_layer.hpp"

namespace miner::world {

inline constexpr const char* kMapFormat = "miner-map-v1";
/// Largest grid a map may have (cells of `resolution` over its bounds): 2^26 cells keep A*'s
/// ~9 bytes per cell near 600 MB and one search within tens of seconds. A map whose resolution
/// gives more is refused (REQ-WORLD-002). (2^28 before issue 20's fifth campaign: a 180-byte
/// .bt of two leaves 639 voxels apart passed it and took 4.9 GB and over a minute to plan on.)
inline constexpr double kMaxGridCells = 67108864.0;
/// The metric range of a map (REQ-WORLD-002; issue 20: a resolution of 1e-300 overflowed the
/// voxel grid's inflation, 1e300 made OctoMap's keys infinite and planning hang, and maps of
/// 1e300 m gave infinite costs). Every reader (JSON, OctoMap, point-cloud import, scans)
/// refuses values outside it, naming the file and field.
/// 1 mm: finer than any mapping sensor's voxel (and 2^26 cells then span only 0.07 m^3).
inline constexpr double kMinResolution = 1e-3;
/// 100 m: coarser cells than any vehicle could plan in.
inline constexpr double kMaxResolution = 100.0;
/// The resolutions a generated family map may be given (`map gen --resolution`): 1 cm to 10 m.
inline constexpr double kMinFamilyResolution = 0.01, kMaxFamilyResolution = 10.0;
/// A vehicle 20 m across; the scan's swept body has the same bound (core/units.hpp).
using miner::kMaxRobotRadius;
/// Throws miner::Error "<field>: ..." unless `resolution` is finite and in [kMinResolution,
/// kMaxResolution].
void check_resolution(double resolution, const std::string& field);
/// Throws miner::Error naming `field` unless the robot radius is finite and in
/// [0, kMaxRobotRadius] m: the range every reader and every query shares (REQ-WORLD-002).
void check_robot_radius(double radius, const std::string& field);

/// A start/goal pair stored with a map (optional extension of miner-map-v1), so a map
/// generated for a benchmark carries the query it was checked against.
struct Query {
  Eigen::Vector3d start;
  Eigen::Vector3d goal;
  double robot_radius = 0.0;
};

/// Cells of the map's grid per axis: ceil(extent / resolution), a face within 1e-9 cells of a
/// whole number of cells snapping onto it (10 m / 0.1 m is 100 cells, not 101), at least 1.
/// Throws miner::Error naming the resolution when the grid would exceed kMaxGridCells (the
/// count in double: no integer wrap) or when the resolution is coarser than an extent.
Eigen::Vector3i grid_dims(const Box& bounds, double resolution);

/// The voxel part of a map: the layer, the policy it is read under, and where it came from.
struct VoxelSource {
  std::shared_ptr<const VoxelLayer> layer;
  UnknownPolicy unknown = UnknownPolicy::kOccupied;
  /// The OctoMap file the layer was read from (absolute), and its SHA-256.
  std::string file;
  std::string sha256;
};

class Map {
 public:
  /// Validates every argument (REQ-WORLD-002); throws miner::Error naming the fault: every
  /// coordinate within kMaxCoordinate, a stored query inside the bounds and free at its robot
  /// radius. With voxels, the resolution must be the layer's and bounds.min must lie on its
  /// lattice (so the A* grid and the voxels share cells), and under the occupied policy the
  /// bounds may not reach beyond the voxels (the space outside them was never observed).
  Map(Box bounds, double resolution, std::vector<Box> obstacles,
      std::optional<Query> query = std::nullopt, std::optional<VoxelSource> voxels = std::nullopt);
  /// A map of voxels alone, bounded by the layer. Throws miner::Error without a layer.
  static Map from_voxels(VoxelSource voxels);
  /// The same map read under another unknown-space policy (the distance field is rebuilt).
  Map with_unknown(UnknownPolicy policy) const;

  /// Loads a `miner-map-v1` JSON file, or an OctoMap `.bt` / `.ot` file by its extension.
  static Map load(const std::string& path);
  /// Parses a `miner-map-v1` document; `origin` names it in error messages and its folder
  /// anchors a relative voxel file.
  static Map from_json(const Json& doc, const std::string& origin);
  /// Where a map file's "voxels.file" lies: relative names are taken from the map file's folder
  /// (`map_path` is the map file), the result absolute and normalised. An empty `file` is refused.
  static std::string voxel_file_path(const std::string& map_path, const std::string& file);
  /// An OctoMap file as a voxel map (world::read_octree), bounded by its known leaves.
  static Map load_octomap(const std::string& path);

  /// The document; a voxel map references its file by absolute path and SHA-256. A voxel map
  /// made in memory (a generated scan) has no file yet: throws miner::Error (save() writes one).
  Json to_json() const;
  /// The voxel file save() writes for a JSON `path` and voxel bytes of SHA-256 `sha256`:
  /// "<stem>.<first 16 hex digits>.bt" beside the file the JSON is written to (a link's target).
  /// Named by content, it is never replaced: a file there with other bytes (a user's) makes the
  /// save refuse (issue 20, sixth campaign: an unrelated x.bt was overwritten; seventeenth
  /// campaign F9: maps and run folders naming an earlier scan's voxels stopped loading).
  static std::string voxel_side_file(const std::string& path, const std::string& sha256);
  /// Writes the map as JSON (atomic), or as an OctoMap `.bt` if `path` ends in .bt. A voxel
  /// map made in memory saved as JSON writes its voxels first to voxel_side_file() beside it,
  /// referenced by file name and SHA-256 (REQ-WORLD-019).
  void save(const std::string& path) const;
  /// The map as voxels at its resolution on the lattice of its bounds: a voxel is occupied if
  /// the grid of VoxelGrid(map, 0) holds it, unknown if the voxel layer says so, else free.
  VoxelLayer to_voxel_layer() const;
  /// Writes to_voxel_layer() as an OctoMap binary tree (free space known, so the bounds survive).
  void save_octomap(const std::string& path) const;

  const Box& bounds() const { return bounds_; }
  double resolution() const { return resolution_; }
  const std::vector<Box>& obstacles() const { return obstacles_; }
  const std::optional<Query>& query() const { return query_; }
  /// The voxel part, or nullptr for a map of boxes only.
  const VoxelObstacles* voxels() const { return voxels_.get(); }
  const std::optional<VoxelSource>& voxel_source() const { return source_; }
  /// The box an obstacle index names: a box obstacle below obstacles().size(), else the voxel
  /// obstacles().size() + i of the layer. Throws miner::Error for an index past both.
  Box obstacle_box(std::size_t index) const;
  /// "obstacle 3 [..]" or "occupied voxel (i, j, k) [..]" / "unknown voxel ...".
  std::string obstacle_name(std::size_t index) const;
  /// A 64-bit digest (FNV-1a) of what the map's collision answers depend on: bounds,
  /// resolution, obstacles, the voxels' states and the unknown-space policy. Two maps with the
  /// same fingerprint answer every query alike; a VoxelGrid keeps its map's, so A* refuses a grid
  /// built for another map (issue 20, tenth campaign L7).
  /// A moved-from Map's is 0, which no constructed map has: its obstacles went with the move,
  /// so a PlanningProblem or grid still pointing at it can tell (twelfth campaign L5: a
  /// problem planned straight through a box on a map moved into a vector).
  std::uint64_t fingerprint() const { return fingerprint_.value; }

  bool in_bounds(const Eigen::Vector3d& p) const { return bounds_.contains(p); }

  /// Index of an obstacle within distance `radius` of p (boundary counts), if any: boxes
  /// first (the lowest index), then blocked voxels (see obstacle_box). Every query below
  /// throws miner::Error for a non-finite point or direction and a radius or range that is
  /// NaN or negative (REQ-WORLD-002: no answer is made up for a point nowhere).
  std::optional<std::size_t> point_collision(const Eigen::Vector3d& p, double radius = 0.0) const;
  /// Index of an obstacle within `radius` of some point of segment [a, b], if any.
  std::optional<std::size_t> segment_collision(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                               double radius = 0.0) const;
  /// A robot of `radius` at p is collision-free and p lies inside the bounds.
  bool is_free(const Eigen::Vector3d& p, double radius = 0.0) const {
    return in_bounds(p) && !point_collision(p, radius);
  }
  /// The segment stays inside the bounds and at distance > radius from every obstacle.
  bool segment_free(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius = 0.0) const {
    return in_bounds(a) && in_bounds(b) && !segment_collision(a, b, radius);
  }

  /// Distance from p to the nearest obstacle (+infinity with no obstacles). p lies within
  /// kMaxCoordinate of the origin on every axis (the squares of farther distances overflow).
  double clearance(const Eigen::Vector3d& p) const;
  /// Distance along the unit direction `dir` (|dir| = 1 within 1e-6, else miner::Error) to the
  /// first obstacle surface within max_range.
  std::optional<double> raycast(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double max_range) const;

  /// Throws miner::Error unless a robot of `radius` can stand at p; `what` names the
  /// point ("start", "goal") and the message names the offending obstacle. The radius must be
  /// a robot radius (check_robot_radius).
  void require_free(const Eigen::Vector3d& p, double radius, const std::string& what) const;

 private:
  Box bounds_;
  double resolution_;
  std::vector<Box> obstacles_;
  std::optional<Query> query_;
  std::optional<VoxelSource> source_;
  std::shared_ptr<const VoxelObstacles> voxels_;
  /// The digest, left 0 in the object a move (construction or assignment) takes it from.
  struct MovedFingerprint {
    std::uint64_t value = 0;
    MovedFingerprint() = default;
    MovedFingerprint(const MovedFingerprint&) = default;
    MovedFingerprint& operator=(const MovedFingerprint&) = default;
    MovedFingerprint(MovedFingerprint&& o) noexcept : value(std::exchange(o.value, 0)) {}
    MovedFingerprint& operator=(MovedFingerprint&& o) noexcept {
      value = std::exchange(o.value, 0);
      return *this;
    }
    ~MovedFingerprint() = default;
  };
  MovedFingerprint fingerprint_;
  void compute_fingerprint();

  /// Broad phase: a uniform grid of buckets over the bounds, each listing the obstacles
  /// that overlap it, so a query visits only nearby obstacles. Answers are identical to
  /// a scan of all obstacles (the lowest colliding index is returned).
  struct BucketGrid {
    Eigen::Vector3d origin;
    double cell = 1.0;
    Eigen::Vector3i dims{1, 1, 1};
    std::vector<std::vector<std::uint32_t>> buckets;
    /// Obstacles spanning more than kMaxBucketsPerObstacle buckets, checked by every query
    /// instead (so n huge boxes cost n entries, not n x 32^3).
    std::vector<std::uint32_t> large;
    /// Obstacles not contained in the bounds: a ray may meet them outside the bounds, where
    /// raycast does not walk the buckets, so it checks them all (usually none).
    std::vector<std::uint32_t> beyond;
    /// Bucket coordinates covering `box` along each axis, clamped to the grid (obstacles
    /// and queries outside the bounds land in the border buckets).
    void span(const Box& box, Eigen::Vector3i& lo, Eigen::Vector3i& hi) const;
    std::size_t at(int x, int y, int z) const {
      return (static_cast<std::size_t>(z) * dims.y() + y) * dims.x() + x;
    }
  };
  BucketGrid index_;
  void build_index();
  /// Lowest index of an obstacle whose squared distance (by `dist2`) to the query is
  /// <= r2, among obstacles in buckets overlapping `region`.
  template <typename Dist2>
  std::optional<std::size_t> query_index(const Box& region, double r2, const Dist2& dist2) const;
};

}  // namespace miner::world
