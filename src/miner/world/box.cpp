#include "miner/world/box.hpp"

#include <algorithm>
#include <cmath>
#include <array>
#include <sstream>
#include <string>

#include "miner/core/error.hpp"
#include "miner/core/text.hpp"

namespace miner::world {

std::optional<std::pair<double, double>> ray_interval(const Box& box, const Eigen::Vector3d& origin,
                                                      const Eigen::Vector3d& dir, double t_max) {
  double t0 = 0.0, t1 = t_max;
  for (int k = 0; k < 3; ++k) {
    if (dir[k] == 0.0) {
      if (origin[k] < box.min[k] || origin[k] > box.max[k]) return std::nullopt;
      continue;
    }
    double ta = (box.min[k] - origin[k]) / dir[k], tb = (box.max[k] - origin[k]) / dir[k];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return std::nullopt;
  }
  return std::pair{t0, t1};
}

double squared_distance(const Eigen::Vector3d& p, const Box& box) {
  double d2 = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double below = box.min[k] - p[k];
    const double above = p[k] - box.max[k];
    const double e = std::max({below, 0.0, above});
    d2 += e * e;
  }
  return d2;
}

double squared_distance(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Box& box) {
  const Eigen::Vector3d d = b - a;
  // Breakpoints of the piecewise quadratic, kept inside (0, 1), plus the ends.
  std::array<double, 8> t{};
  int n = 0;
  t[n++] = 0.0;
  t[n++] = 1.0;
  for (int k = 0; k < 3; ++k) {
    if (d[k] == 0.0) continue;
    for (const double face : {box.min[k], box.max[k]}) {
      const double tk = (face - a[k]) / d[k];
      if (tk > 0.0 && tk < 1.0) t[n++] = tk;
    }
  }
  // Insertion sort: at most 8 values (and std::sort trips a GCC 12 -Warray-bounds false positive).
  for (int i = 1; i < n; ++i) {
    const double v = t[i];
    int j = i;
    for (; j > 0 && t[j - 1] > v; --j) t[j] = t[j - 1];
    t[j] = v;
  }

  const auto f = [&](double s) { return squared_distance(Eigen::Vector3d(a + s * d), box); };
  double best = f(t[0]);
  for (int i = 0; i + 1 < n; ++i) {
    best = std::min(best, f(t[i + 1]));
    const double lo = t[i], hi = t[i + 1];
    if (hi <= lo) continue;
    // On (lo, hi) each axis is entirely below, inside or above the slab: the piece is
    // q(s) = sum_{active k} (a_k + s d_k - face_k)^2, minimised at s* = -sum(e_k d_k)/sum(d_k^2).
    const Eigen::Vector3d mid = a + (0.5 * (lo + hi)) * d;
    double num = 0.0, den = 0.0;
    for (int k = 0; k < 3; ++k) {
      double face = 0.0;
      if (mid[k] < box.min[k]) face = box.min[k];
      else if (mid[k] > box.max[k]) face = box.max[k];
      else continue;
      num += (a[k] - face) * d[k];
      den += d[k] * d[k];
    }
    if (den > 0.0) {
      const double s = -num / den;
      if (s > lo && s < hi) best = std::min(best, f(s));
    } else {
      // Every axis inside its slab: the piece runs through the box, distance 0 at its middle.
      // Its ends lie on faces up to rounding and may measure 1e-32 outside (twelfth campaign L4:
      // at radius 0 a segment through a box was "free" one way and not the other).
      best = std::min(best, f(0.5 * (lo + hi)));
    }
  }
  return best;
}

void check_query_point(const Eigen::Vector3d& p, const char* field) {
  if (!p.allFinite()) require_finite(p, field);
}

void check_query_direction(const Eigen::Vector3d& dir, const char* field) {
  check_query_point(dir, field);
  // |dir| of a normalised vector is 1 within a few ulps; 1e-6 forgives a float-made direction.
  constexpr double kUnitTolerance = 1e-6;
  const double n = dir.norm();
  if (!(std::abs(n - 1.0) <= kUnitTolerance))
    throw Error(std::string(field) + ": must be a unit vector (the distance is measured along it), got length " +
                short_number(n));
}

void require_within_range(const Eigen::Vector3d& p, const char* what, const char* why) {
  if (p.cwiseAbs().maxCoeff() <= kMaxCoordinate) return;
  std::ostringstream os;
  os << what << ": " << format_point(p) << " lies farther than " << kMaxCoordinate << " m from the origin" << why;
  throw Error(os.str());
}

void check_query_radius(double radius, const char* field) {
  if (!(radius >= 0.0)) throw Error(std::string(field) + ": must be a number >= 0, got " + exact_number(radius));
}

}  // namespace miner::world
