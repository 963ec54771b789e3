#pragma once
/// \file
/// Voxel maps as a mapping run leaves them (REQ-WORLD-012, REQ-WORLD-013).
///
/// A VoxelLayer is a dense grid of three-state voxels on the lattice of its resolution:
/// voxel (i, j, k) is the closed cube (origin_cells + (i, j, k) + [0, 1]^3) * resolution, so
/// its centre is exactly OctoMap's keyToCoord(key) for key = origin_cells + (i, j, k) + 2^15
/// (in double, from the key, depth and resolution: no float rounding, no inflation).
///
/// VoxelObstacles is a layer read under an unknown-space policy: the voxels it *blocks* are the
/// occupied ones, and the unknown ones too under UnknownPolicy::kOccupied (the default for
/// planning and flight). Collision and clearance queries go through an exact Euclidean distance
/// transform of the blocked voxels' centres (Felzenszwalb & Huttenlocher, "Distance transforms of
/// sampled functions", 2012): with d_c the distance from the centre of cell c to the nearest
/// blocked centre, every point p has
///     dist(p, blocked cubes) >= d_c - |p - centre_c| - (sqrt 3 / 2) res          (bound B)
/// (triangle inequality; no point of a cube lies farther than half its diagonal from its
/// centre). Queries that B decides cost O(1); only points within ~1.7 voxels of the robot's
/// radius of an obstacle are decided exactly, against the voxel cubes themselves (box distance,
/// REQ-WORLD-004/005), so answers are exact, not a grid approximation.

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "miner/world/box.hpp"

namespace miner::world {

enum class VoxelState : std::uint8_t { kFree = 0, kOccupied = 1, kUnknown = 2 };

/// What planning, A*, the heuristic and the flight make of unknown space.
enum class UnknownPolicy { kOccupied, kFree };
/// "occupied" or "free"; anything else throws miner::Error naming `what`.
UnknownPolicy parse_unknown_policy(const std::string& text, const std::string& what);
const char* to_string(UnknownPolicy policy);

class VoxelLayer {
 public:
  /// `states` holds dims.prod() VoxelState values, x fastest. Throws miner::Error on a
  /// non-positive or non-finite resolution, empty dims, more than kMaxGridCells voxels, a
  /// state size that does not match, or a state byte that is not a VoxelState.
  VoxelLayer(Eigen::Vector3i origin_cells, double resolution, Eigen::Vector3i dims, std::vector<std::uint8_t> states);

  const Eigen::Vector3i& origin_cells() const { return origin_cells_; }
  Eigen::Vector3d origin() const { return origin_cells_.cast<double>() * resolution_; }
  double resolution() const { return resolution_; }
  const Eigen::Vector3i& dims() const { return dims_; }
  std::size_t size() const { return states_.size(); }
  const std::vector<std::uint8_t>& states() const { return states_; }

  std::size_t index(int i, int j, int k) const {
    return (static_cast<std::size_t>(k) * static_cast<std::size_t>(dims_.y()) + static_cast<std::size_t>(j)) *
               static_cast<std::size_t>(dims_.x()) +
           static_cast<std::size_t>(i);
  }
  Eigen::Vector3i coords(std::size_t idx) const;
  VoxelState state(std::size_t idx) const { return static_cast<VoxelState>(states_[idx]); }
  std::size_t count(VoxelState s) const;

  /// The closed box the layer covers.
  Box bounds() const;
  /// The closed cube of voxel c (exact multiples of the resolution).
  Box cell_box(const Eigen::Vector3i& c) const;
  Eigen::Vector3d cell_center(const Eigen::Vector3i& c) const;
  /// The voxel holding p, clamped onto the layer (points outside map to the nearest voxel).
  Eigen::Vector3i clamped_cell(const Eigen::Vector3d& p) const;

 private:
  Eigen::Vector3i origin_cells_;
  double resolution_;
  Eigen::Vector3i dims_;
  std::vector<std::uint8_t> states_;
};

/// Exact squared Euclidean distance transform of a dims grid (x fastest) to its cells with
/// seeds != 0, in cells (+inf with no seed): between cell centres, or with cube_to_cube the
/// distance between the closed unit cubes, sum_k max(|dk| - 1, 0)^2 (each axis' 1D transform
/// runs on its input eroded by one cell, which is that metric's separable form).
std::vector<double> squared_distance_transform(const std::vector<std::uint8_t>& seeds, const Eigen::Vector3i& dims,
                                               bool cube_to_cube);

/// Occupied voxels drawn coarsely for a viewer: blocks of f^3 voxels (f = 1, 2, 4, ...; the
/// smallest f giving at most `max_boxes` boxes) holding any occupied voxel, runs of such blocks
/// along x merged into one box. `block` receives f. A picture, not an obstacle set: a block is
/// drawn whole when one of its voxels is occupied.
std::vector<Box> decimated_occupied_boxes(const VoxelLayer& layer, std::size_t max_boxes, int* block = nullptr);

class VoxelObstacles {
 public:
  VoxelObstacles(std::shared_ptr<const VoxelLayer> layer, UnknownPolicy policy);

  const VoxelLayer& layer() const { return *layer_; }
  const std::shared_ptr<const VoxelLayer>& layer_ptr() const { return layer_; }
  UnknownPolicy policy() const { return policy_; }
  bool blocked(std::size_t idx) const { return blocked_[idx] != 0; }
  std::size_t blocked_count() const { return blocked_count_; }
  /// Distance from voxel idx's centre to the nearest blocked voxel's centre, in voxels (0 for
  /// a blocked voxel, +inf when none is blocked; float-rounded).
  float centre_distance(std::size_t idx) const {
    return blocked_count_ == 0 ? std::numeric_limits<float>::infinity() : distance_[idx];
  }

  /// Bound B of the file comment: no blocked cube lies within this distance of p.
  double distance_lower_bound(const Eigen::Vector3d& p) const;
  /// A blocked voxel within `radius` of p (boundary counts): the one holding p if it is
  /// blocked, else the lowest index among them.
  std::optional<std::size_t> point_hit(const Eigen::Vector3d& p, double radius) const;
  /// A blocked voxel within `radius` of some point of [a, b]. The segment is walked by
  /// bound B (sphere tracing); pieces of one voxel's length where B cannot decide are
  /// tested exactly against the blocked cubes near them.
  std::optional<std::size_t> segment_hit(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius) const;
  /// Exact distance from p to the nearest blocked cube (+infinity when none is blocked).
  double clearance(const Eigen::Vector3d& p) const;
  /// Distance along the unit direction `dir` from `origin` to the first blocked cube, if one
  /// lies within `max_range` (a 3D DDA through the voxels: Amanatides & Woo 1987).
  std::optional<double> raycast(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double max_range) const;
  /// Bytes held by the blocked mask and the distance field (the layer itself excluded).
  std::size_t field_bytes() const { return blocked_.size() + distance_.size() * sizeof(float); }

 private:
  std::shared_ptr<const VoxelLayer> layer_;
  UnknownPolicy policy_;
  std::vector<std::uint8_t> blocked_;
  std::size_t blocked_count_ = 0;
  /// Distance from each voxel centre to the nearest blocked centre, in voxels (float: exact
  /// to ~6e-8 relative; bound B subtracts that rounding).
  std::vector<float> distance_;
  /// The blocked voxel whose cube holds p (the clamped cell, so points on a face may name
  /// either neighbour's), if any.
  std::optional<std::size_t> containing_blocked(const Eigen::Vector3d& p) const;
  /// Blocked voxels whose cube lies within `radius` of some point of [a, b], voxels of the
  /// box [min(a,b) - radius, max(a,b) + radius]; the lowest index.
  std::optional<std::size_t> exact_hit(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius) const;
};

}  // namespace miner::world
