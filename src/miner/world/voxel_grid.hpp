#pragma once
/// \file
/// Voxel occupancy grid of a Map at its resolution, for a robot of radius r
/// (REQ-WORLD-006).
///
/// Cell (i, j, k) is the open cube origin + ([i, i+1) x [j, j+1) x [k, k+1)) * res with
/// origin = bounds.min and dims = ceil(extent / res). A cell is occupied iff its open
/// interior meets an obstacle box (or blocked voxel, REQ-WORLD-012) inflated by r on every
/// side, or its centre lies outside the bounds. The grid is conservative: it covers the exact rounded-box
/// inflation, so a straight move between free cells that A* allows is collision-free
/// in the continuous map (REQ-WORLD-008).

#include <cstddef>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace miner::world {

class Map;
class VoxelObstacles;
struct Box;

class VoxelGrid {
 public:

  VoxelGrid(const Map& map, double robot_radius);

  const Eigen::Vector3i& dims() const { return dims_; }
  const Eigen::Vector3d& origin() const { return origin_; }
  double resolution() const { return resolution_; }
  double robot_radius() const { return robot_radius_; }
  /// The fingerprint of the map the grid was built from (Map::fingerprint).
  std::uint64_t map_fingerprint() const { return map_fingerprint_; }
  std::size_t cell_count() const { return occupancy_.size(); }
  std::size_t occupied_count() const;

  std::size_t index(int i, int j, int k) const {
    return (static_cast<std::size_t>(k) * dims_.y() + j) * dims_.x() + i;
  }
  std::size_t index(const Eigen::Vector3i& c) const { return index(c.x(), c.y(), c.z()); }
  Eigen::Vector3i coords(std::size_t idx) const;
  bool contains(const Eigen::Vector3i& c) const {
    return (c.array() >= 0).all() && (c.array() < dims_.array()).all();
  }
  bool occupied(std::size_t idx) const { return occupancy_[idx] != 0; }
  bool occupied(const Eigen::Vector3i& c) const { return occupancy_[index(c)] != 0; }

  Eigen::Vector3d cell_center(std::size_t idx) const;
  Eigen::Vector3d cell_center(const Eigen::Vector3i& c) const {
    return origin_ + (c.cast<double>().array() + 0.5).matrix() * resolution_;
  }
  /// The cell containing p (the last cell for p on the upper bound), if p is in bounds.
  std::optional<Eigen::Vector3i> cell_of(const Eigen::Vector3d& p) const;

 private:
  Eigen::Vector3i dims_;
  Eigen::Vector3d origin_;
  double resolution_;
  double robot_radius_;
  std::uint64_t map_fingerprint_;
  std::vector<std::uint8_t> occupancy_;
  /// Blocked voxels of a voxel map, grown by the robot radius like the boxes.
  void mark_voxels(const VoxelObstacles& voxels, const Box& bounds);
  /// Marks every cell of the blocks (first, last cell per axis, inclusive) occupied.
  void mark_blocks(const std::vector<std::pair<Eigen::Vector3i, Eigen::Vector3i>>& blocks);
};

}  // namespace miner::world
