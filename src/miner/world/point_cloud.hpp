#pragma once
/// \file
/// Point clouds in (REQ-WORLD-018): PLY and PCD files read by MINER's own bounded readers, then
/// integrated into an OctoMap by OctoMap's own ray casting (insertPointCloud: the voxels on the
/// ray from the sensor to each point are free, the point's voxel occupied), so a cloud becomes a
/// voxel map with free, occupied and unknown space.
///
/// PLY: `format ascii 1.0`, `binary_little_endian 1.0` or `binary_big_endian 1.0`; the `vertex`
/// element must come first and hold float or double properties x, y, z (any other scalar
/// properties are skipped; list properties are refused in the vertex element).
/// PCD (v0.7): `DATA ascii` or `DATA binary` (binary_compressed is refused by name); FIELDS with x,
/// y, z of TYPE F and SIZE 4 or 8; the VIEWPOINT's translation is the sensor origin unless one is
/// given. Points with a NaN or infinite coordinate (PCD's "no return") are skipped and counted.
/// Every size is checked against the bytes present before anything is allocated; at most
/// kMaxCloudPoints points.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "miner/world/voxel_layer.hpp"

namespace miner::world {

inline constexpr std::size_t kMaxCloudPoints = std::size_t{1} << 27;

struct PointCloud {
  std::vector<Eigen::Vector3d> points;
  std::size_t skipped = 0;                    ///< non-finite points left out
  std::optional<Eigen::Vector3d> viewpoint;   ///< PCD VIEWPOINT translation
};

/// Reads a .ply or .pcd file (by extension); throws miner::Error naming the file and the fault.
PointCloud read_point_cloud(const std::string& path);
/// Parses the bytes of a cloud; `ply` selects the format, `origin` names it in messages.
PointCloud parse_point_cloud(const std::string& bytes, bool ply, const std::string& origin);

struct CloudScan {
  PointCloud cloud;
  Eigen::Vector3d origin;  ///< sensor position the rays start from
  std::string name;        ///< the file it came from, named in messages (empty: "cloud <i>")
};

/// Integrates the scans with OctoMap at `resolution` (rays longer than max_range, if positive,
/// mark free space up to it and no occupied end; 0: no limit) into a voxel layer. Throws when
/// the resolution is not positive and finite, max_range is NaN, infinite or negative, a point
/// is not finite (the readers skip such points; a cloud filled in code must too), a point or
/// origin lies beyond OctoMap's key range, or no voxel becomes known.
std::shared_ptr<const VoxelLayer> integrate_clouds(const std::vector<CloudScan>& scans, double resolution,
                                                   double max_range);

}  // namespace miner::world
