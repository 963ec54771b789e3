#pragma once
/// \file
/// A simulated mapping run (REQ-WORLD-016): a range sensor flown along a path through any map
/// casts rays, and OctoMap integrates them as a real mapping run would (free along each ray,
/// occupied at its end point, unknown where no ray went).
///
/// Sensor model, per pose (poses every `spacing` m along the path, heading along it): a grid
/// of h_rays x v_rays rays over a horizontal field of view centred on the heading and a
/// vertical one centred on the horizon, like a spinning lidar (360 x 30 deg) or a depth camera
/// (90 x 60). A ray returns the first obstacle surface within `range` (Map::raycast), its
/// distance disturbed by N(0, noise^2); a return is dropped with probability `dropout` (no
/// information at all, as dark or specular surfaces give); a ray that meets nothing within the
/// range, or leaves the map's bounds first, marks free space up to there and nothing at its end.
/// At the first and last pose the sensor turns a full circle (spin_at_ends, at the same angular
/// spacing). The volume the vehicle swept along the path (body_radius plus one voxel) is set
/// free afterwards, except voxels an obstacle meets (within the half diagonal of the voxel's
/// centre): the vehicle was there, and a return on a surface stays occupied.
/// Each pose's rays are integrated as one scan (a voxel both crossed and hit counts as hit,
/// OctoMap's insertPointCloud rule), with OctoMap's default sensor model (hit 0.7, miss 0.4).
/// Randomness comes from Rng(seed, pose index) only: the same inputs give the same bytes.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "miner/world/map.hpp"

namespace miner::world {

/// Most rays one scan may cast (poses x rays per pose): ~10 minutes of OctoMap integration.
inline constexpr double kMaxScanRays = 1e8;

struct ScanOptions {
  double range = 8.0;          ///< m
  double h_fov_deg = 360.0;    ///< horizontal field of view, (0, 360]
  double v_fov_deg = 60.0;     ///< vertical field of view, [0, 180)
  int h_rays = 180;            ///< rays across the horizontal field
  int v_rays = 16;             ///< rays across the vertical field
  double noise = 0.02;         ///< range noise standard deviation, m
  double dropout = 0.02;       ///< probability that a return is lost
  double spacing = 1.0;        ///< distance between poses along the path, m
  double resolution = 0.0;     ///< voxel size of the scan; 0: the map's
  double body_radius = 0.0;    ///< voxels within this (+ one voxel) of the path are free: the vehicle was there
  bool spin_at_ends = true;    ///< a full horizontal turn at the first and the last pose
  std::uint64_t seed = 1;
};

struct ScanResult {
  std::shared_ptr<const VoxelLayer> layer;  ///< the voxels the run leaves
  std::string bt;              ///< the same as an OctoMap binary tree (the bytes OctoMap writes)
  std::size_t poses = 0;
  std::size_t rays = 0;
  std::size_t returns = 0;     ///< rays that hit a surface and were not dropped
};

/// Checks the options (each field named on error) and the path (at least one point, every
/// point inside the map's bounds); throws miner::Error. Bounded work: at most 1e8 rays.
void validate_scan(const ScanOptions& options, const Map& map, const std::vector<Eigen::Vector3d>& path);

/// Most rays a scan casts along a route of `length` m: h_rays x v_rays at every pose (one each
/// `spacing` m, both ends included), except that with spin_at_ends the first and the last pose
/// cast the full turn's ceil(h_rays 360 / h_fov) x v_rays instead. validate_scan bounds it
/// by kMaxScanRays; the CLI checks the options alone with length 0 (the ends' poses).
double scan_ray_bound(const ScanOptions& options, double length);

/// Flies the sensor along `path` (a polyline) through `map` and builds the scan.
ScanResult scan_map(const Map& map, const std::vector<Eigen::Vector3d>& path, const ScanOptions& options);

/// Points every `spacing` m along a polyline, its first and last point included.
std::vector<Eigen::Vector3d> resample_path(const std::vector<Eigen::Vector3d>& path, double spacing);

}  // namespace miner::world
