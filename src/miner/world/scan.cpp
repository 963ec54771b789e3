#include "miner/world/scan.hpp"

#include <cmath>
#include <iostream>
#include <sstream>

#include <octomap/OcTree.h>

#include "miner/core/error.hpp"
#include "miner/core/text.hpp"
#include "miner/core/rng.hpp"
#include "miner/world/octree_leaves.hpp"

namespace miner::world {

namespace {

constexpr double kDegree = M_PI / 180.0;
constexpr double kMaxRays = kMaxScanRays;
/// Most voxels all rays together may cross (OctoMap integrates ~1e7 per second).
constexpr double kMaxRaySteps = 2e9;
/// Most voxel tests the body sweep may make (poses every half voxel x the (2n + 1)^3 cube around
/// each): ~1.4e8 per second here, so about 4 s (issue 20, eighth campaign UB1: --body-radius 10
/// at 0.1 m took 2e9 tests, 15-60 s, outside the stated bounds).
constexpr double kMaxSweepTests = 5e8;

void check(bool ok, const std::string& field, const std::string& what) {
  if (!ok) throw Error("scan " + field + ": " + what);
}

/// Distance along the unit direction `dir` from p (inside the box) to where it leaves the box.
double exit_distance(const Box& box, const Eigen::Vector3d& p, const Eigen::Vector3d& dir) {
  double t = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    if (dir[k] > 0.0) t = std::min(t, (box.max[k] - p[k]) / dir[k]);
    if (dir[k] < 0.0) t = std::min(t, (box.min[k] - p[k]) / dir[k]);
  }
  return std::max(0.0, t);
}

}  // namespace

std::vector<Eigen::Vector3d> resample_path(const std::vector<Eigen::Vector3d>& path, double spacing) {
  std::vector<Eigen::Vector3d> out;
  if (path.empty()) return out;
  out.push_back(path.front());
  double carried = 0.0;  // distance travelled since the last pose
  for (std::size_t i = 1; i < path.size(); ++i) {
    const Eigen::Vector3d a = path[i - 1], b = path[i];
    const double len = (b - a).norm();
    double s = spacing - carried;
    while (s <= len) {
      out.push_back(a + (b - a) * (s / len));
      s += spacing;
    }
    carried = len - (s - spacing);
  }
  if ((out.back() - path.back()).norm() > 1e-9) out.push_back(path.back());
  return out;
}

void validate_scan(const ScanOptions& o, const Map& map, const std::vector<Eigen::Vector3d>& path) {
  check(std::isfinite(o.range) && o.range > 0.0 && o.range <= 1000.0, "range", "must lie in (0, 1000] m");
  check(std::isfinite(o.h_fov_deg) && o.h_fov_deg > 0.0 && o.h_fov_deg <= 360.0, "horizontal field of view",
        "must lie in (0, 360] degrees");
  check(std::isfinite(o.v_fov_deg) && o.v_fov_deg >= 0.0 && o.v_fov_deg < 180.0, "vertical field of view",
        "must lie in [0, 180) degrees");
  check(o.h_rays >= 1 && o.h_rays <= 100000, "horizontal rays", "must lie in [1, 100000]");
  check(o.v_rays >= 1 && o.v_rays <= 100000, "vertical rays", "must lie in [1, 100000]");
  check(std::isfinite(o.noise) && o.noise >= 0.0 && o.noise <= 0.5 * o.range, "noise",
        "must lie in [0, range / 2] m (noise " + short_number(o.noise) + " m, range " + short_number(o.range) +
            " m): lower the noise or raise the range");
  check(std::isfinite(o.dropout) && o.dropout >= 0.0 && o.dropout < 1.0, "dropout", "must lie in [0, 1)");
  check(std::isfinite(o.spacing) && o.spacing > 0.0, "spacing", "must be positive");
  check(std::isfinite(o.resolution) && o.resolution >= 0.0, "resolution", "must be positive (or 0: the map's)");
  check(std::isfinite(o.body_radius) && o.body_radius >= 0.0 && o.body_radius <= 10.0, "body radius",
        "must lie in [0, 10] m");
  check(!path.empty(), "path", "is empty");
  double length = 0.0;
  for (std::size_t i = 0; i < path.size(); ++i) {
    require_finite(path[i], "scan path point " + std::to_string(i));
    if (!map.in_bounds(path[i]))
      throw Error("scan path point " + std::to_string(i) + " " + format_point(path[i]) + " lies outside the map bounds");
    if (i > 0) length += (path[i] - path[i - 1]).norm();
  }
  const double rays = scan_ray_bound(o, length);
  if (rays > kMaxRays) {
    std::ostringstream os;
    os << "scan: " << rays << " rays (poses every " << o.spacing << " m over " << length << " m, " << o.h_rays << " x "
       << o.v_rays << " rays each) exceed the " << kMaxRays << " a scan may cast; use fewer rays or a larger spacing";
    throw Error(os.str());
  }
  const double res = o.resolution > 0.0 ? o.resolution : map.resolution();
  check_resolution(res, "scan resolution");
  (void)grid_dims(map.bounds(), res);  // the scan's layer over the map must be a grid a map may have
  // Each ray walks up to min(range, the map's diagonal) / res voxels: bound the walk too.
  const double steps = rays * std::min(o.range, map.bounds().extent().norm()) / res;
  if (steps > kMaxRaySteps) {
    std::ostringstream os;
    os << "scan: " << rays << " rays of up to " << std::min(o.range, map.bounds().extent().norm()) << " m at " << res
       << " m would walk " << steps << " voxels, more than the " << kMaxRaySteps
       << " a scan may; use fewer rays, a shorter range or a coarser resolution";
    throw Error(os.str());
  }
  if (o.body_radius > 0.0) {
    const double side = 2.0 * (std::ceil(o.body_radius / res) + 1.0) + 1.0;
    const double tests = (std::floor(length / (0.5 * res)) + 2.0) * side * side * side;
    if (tests > kMaxSweepTests) {
      std::ostringstream os;
      os << "scan: the body sweep (body radius " << o.body_radius << " m at " << res << " m voxels over " << length
         << " m) would test " << tests << " voxels, more than the " << kMaxSweepTests
         << " a scan may; use a smaller body radius or a coarser resolution";
      throw Error(os.str());
    }
  }
  // OctoMap keys are 16 bits: the map must lie within 32768 voxels of the origin.
  const double reach = std::max(map.bounds().min.cwiseAbs().maxCoeff(), map.bounds().max.cwiseAbs().maxCoeff());
  if (reach / res >= 32767.0) {
    std::ostringstream os;
    os << "scan resolution: " << res << " m puts the map's bounds (" << reach
       << " m from the origin) outside OctoMap's 32768 voxels; use a coarser resolution";
    throw Error(os.str());
  }
}

double scan_ray_bound(const ScanOptions& o, double length) {
  const double per_pose = static_cast<double>(o.h_rays) * static_cast<double>(o.v_rays);
  const double poses = std::floor(length / o.spacing) + 2.0;  // resample_path: every spacing, and the end
  // A turning end pose casts its full circle instead of its field of view (scan_map).
  const double turn_pose = std::ceil(o.h_rays * 360.0 / o.h_fov_deg) * static_cast<double>(o.v_rays);
  return poses * per_pose + (o.spin_at_ends ? 2.0 * (turn_pose - per_pose) : 0.0);
}

ScanResult scan_map(const Map& map, const std::vector<Eigen::Vector3d>& path, const ScanOptions& o) {
  validate_scan(o, map, path);
  const double res = o.resolution > 0.0 ? o.resolution : map.resolution();
  octomap::OcTree tree(res);
  ScanResult result;
  const std::vector<Eigen::Vector3d> poses = resample_path(path, o.spacing);
  const auto point = [](const Eigen::Vector3d& p) {
    return octomap::point3d(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
  };
  octomap::KeyRay ray;
  for (std::size_t k = 0; k < poses.size(); ++k) {
    Rng rng(o.seed, k);
    const Eigen::Vector3d origin = poses[k];
    // Heading along the path (towards the next pose, or from the previous one at the end).
    Eigen::Vector3d ahead = k + 1 < poses.size() ? Eigen::Vector3d(poses[k + 1] - origin)
                                                 : (k > 0 ? Eigen::Vector3d(origin - poses[k - 1]) : Eigen::Vector3d::UnitX());
    const double yaw = std::hypot(ahead.x(), ahead.y()) > 1e-9 ? std::atan2(ahead.y(), ahead.x()) : 0.0;
    octomap::KeySet free_cells, hit_cells;
    // At the first and the last pose the vehicle turns once on the spot (a full circle at the
    // same angular spacing), as a mapping run does before it sets off and when it arrives.
    const bool spin = o.spin_at_ends && (k == 0 || k + 1 == poses.size());
    const double h_fov = spin ? 360.0 : o.h_fov_deg;
    const int h_rays = spin ? static_cast<int>(std::ceil(o.h_rays * 360.0 / o.h_fov_deg)) : o.h_rays;
    for (int i = 0; i < h_rays; ++i) {
      const double az = yaw + (-0.5 * h_fov + (i + 0.5) * h_fov / h_rays) * kDegree;
      for (int j = 0; j < o.v_rays; ++j) {
        const double el = (-0.5 * o.v_fov_deg + (j + 0.5) * o.v_fov_deg / o.v_rays) * kDegree;
        const Eigen::Vector3d dir(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
        ++result.rays;
        // Just inside the bounds: a ray leaving through a face ends in the voxel on this side of it.
        const double reach = std::min(o.range, exit_distance(map.bounds(), origin, dir) - 1e-6 * res);
        const std::optional<double> hit = map.raycast(origin, dir, reach);
        const double noisy = hit ? *hit + o.noise * rng.normal() : 0.0;
        const bool dropped = rng.uniform01() < o.dropout;
        if (hit && dropped) continue;
        if (hit && noisy > 0.0 && noisy <= o.range) {
          const Eigen::Vector3d end = origin + noisy * dir;
          ++result.returns;
          if (tree.computeRayKeys(point(origin), point(end), ray)) free_cells.insert(ray.begin(), ray.end());
          octomap::OcTreeKey key;
          if (tree.coordToKeyChecked(point(end), key)) hit_cells.insert(key);
        } else if (!hit) {
          if (tree.computeRayKeys(point(origin), point(origin + reach * dir), ray))
            free_cells.insert(ray.begin(), ray.end());
        }
      }
    }
    for (const auto& key : free_cells)
      if (!hit_cells.count(key)) tree.updateNode(key, false, true);
    for (const auto& key : hit_cells) tree.updateNode(key, true, true);
  }
  // The volume the vehicle swept along the path is free: it was there (mapping pipelines clear
  // it too). Set, not voted: a noisy return inside it cannot outweigh the vehicle's presence.
  if (o.body_radius > 0.0) {
    constexpr double kVoxelCircumradius = 0.8660254037844387;  // sqrt(3) / 2: a unit cube's half diagonal
    // OctoMap's float voxel centres (~4e-6 m off at 100 m): a margin in voxels over the rounding.
    constexpr double kCentreRounding = 1e-4;
    const int n = static_cast<int>(std::ceil(o.body_radius / res)) + 1;
    octomap::KeySet swept;
    for (const Eigen::Vector3d& p : resample_path(path, 0.5 * res)) {
      octomap::OcTreeKey centre;
      if (!tree.coordToKeyChecked(point(p), centre)) continue;
      for (int dz = -n; dz <= n; ++dz)
        for (int dy = -n; dy <= n; ++dy)
          for (int dx = -n; dx <= n; ++dx) {
            const octomap::OcTreeKey key(static_cast<octomap::key_type>(centre[0] + dx),
                                         static_cast<octomap::key_type>(centre[1] + dy),
                                         static_cast<octomap::key_type>(centre[2] + dz));
            if (swept.count(key)) continue;
            const octomap::point3d c = tree.keyToCoord(key);
            const Eigen::Vector3d cd(c.x(), c.y(), c.z());
            // Only voxels that meet no obstacle (the sphere around the cube clear): a voxel an
            // obstacle surface meets keeps what the rays saw, so a body wider than the path's
            // clearance never erases a return (issue 20, sixth campaign: --body-radius 1 on a
            // path planned for 0.2 m freed 884 occupied voxels).
            if ((cd - p).norm() <= o.body_radius + res && map.is_free(cd, (kVoxelCircumradius + kCentreRounding) * res))
              swept.insert(key);
          }
    }
    for (const auto& key : swept) tree.setNodeValue(key, tree.getClampingThresMinLog(), true);
  }
  tree.updateInnerOccupancy();
  result.layer = layer_of_tree(tree, "scan");
  result.bt = octree_bt_bytes(*result.layer);
  result.poses = poses.size();
  return result;
}

}  // namespace miner::world
