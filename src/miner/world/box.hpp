#pragma once
/// \file
/// Axis-aligned boxes and exact distance queries (REQ-WORLD-004, REQ-WORLD-005).
///
/// A box is the closed set B = [min, max] (a point on its boundary is inside).
/// A robot of radius r at p collides with B iff dist(p, B) <= r, i.e. p lies in the
/// Minkowski sum of B and the closed ball of radius r (a rounded box), so queries
/// with a radius are exact, not a box-inflated approximation.

#include <optional>
#include <utility>

#include <Eigen/Core>

namespace miner::world {

/// 1000 km from the origin: double then keeps metres to ~1e-10 m, and a map of the Earth's
/// scale still fits; beyond it a local frame is what the user needs.
inline constexpr double kMaxCoordinate = 1e6;

struct Box {
  Eigen::Vector3d min;
  Eigen::Vector3d max;

  /// The box grown by r on every side (a conservative cover of the rounded box).
  Box inflated(double r) const { return {min.array() - r, max.array() + r}; }
  bool contains(const Eigen::Vector3d& p) const {
    return (p.array() >= min.array()).all() && (p.array() <= max.array()).all();
  }
  /// Closed boxes overlap (touching counts).
  bool overlaps(const Box& o) const {
    return (min.array() <= o.max.array()).all() && (o.min.array() <= max.array()).all();
  }
  Eigen::Vector3d center() const { return 0.5 * (min + max); }
  Eigen::Vector3d extent() const { return max - min; }
  double volume() const { return extent().prod(); }
};

/// Slab test: the interval [t0, t1] within [0, t_max] on which the ray origin + t dir lies in
/// the closed box, or nullopt when there is none. An axis with dir_k = 0 keeps the ray in
/// the box's slab or misses it; the arithmetic is monotone in the box's faces, so a box
/// inside another is entered no earlier and left no later.
std::optional<std::pair<double, double>> ray_interval(const Box& box, const Eigen::Vector3d& origin,
                                                      const Eigen::Vector3d& dir, double t_max);

/// dist(p, B)^2 = sum_k max(min_k - p_k, 0, p_k - max_k)^2.
double squared_distance(const Eigen::Vector3d& p, const Box& box);

/// min over t in [0,1] of dist(a + t (b - a), B)^2.
///
/// f(t) = dist(a + t d, B)^2 is convex and piecewise quadratic in t, with breakpoints
/// where a coordinate crosses a face plane (at most 6). Its minimum is attained at
/// t = 0, t = 1, a breakpoint, or the stationary point of one quadratic piece; all
/// these candidates are evaluated exactly, so the result is exact up to rounding.
double squared_distance(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Box& box);

/// The argument checks of every geometric query (Map's and VoxelObstacles'): a point or
/// direction is finite, a radius or range a number >= 0; otherwise an Error naming `field`.
/// Tenth campaign L1: a NaN point read a voxel layer at cell -2^31. Cheap when they hold (no
/// string is built), so the hot queries call them each time.
void check_query_point(const Eigen::Vector3d& p, const char* field);
void check_query_radius(double radius, const char* field);
/// A ray's direction is a finite unit vector (within kUnitTolerance): the distance a raycast
/// answers is measured along it (eleventh campaign L2: a direction of length 10 answered a
/// tenth of the distance, a zero one "nothing within range").
void check_query_direction(const Eigen::Vector3d& dir, const char* field);
/// Refuses a point farther than kMaxCoordinate from the origin on some axis, naming it:
/// "<what>: (x, y, z) lies farther than 1e+06 m from the origin<why>". Map bounds, region bounds
/// and clearance queries (at 1e155 m its square overflowed to +infinity: eleventh campaign P3)
/// share it; cheap when the point is within range.
void require_within_range(const Eigen::Vector3d& p, const char* what, const char* why);

}  // namespace miner::world
