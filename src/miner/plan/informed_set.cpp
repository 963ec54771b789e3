#include "miner/plan/informed_set.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "miner/core/error.hpp"
#include "miner/core/rng.hpp"

namespace miner::plan {

ProlateHyperspheroid::ProlateHyperspheroid(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double c)
    : a_(a), b_(b), centre_(0.5 * (a + b)) {
  // Tenth campaign L17: NaN or infinite foci or diameter gave NaN samples.
  require_finite(a, "informed set: focus a");
  require_finite(b, "informed set: focus b");
  require_finite(c, "informed set: transverse diameter c");
  const double c_min = (b - a).norm();
  c_ = std::max(c, c_min);
  r1_ = 0.5 * c_;
  r2_ = 0.5 * std::sqrt(std::max(c_ * c_ - c_min * c_min, 0.0));
  // Orthonormal frame with the focal axis first (Gram-Schmidt against the coordinate
  // axis least aligned with it).
  Eigen::Vector3d e1 = c_min > 0.0 ? Eigen::Vector3d((b - a) / c_min) : Eigen::Vector3d::UnitX();
  Eigen::Index least = 0;
  e1.cwiseAbs().minCoeff(&least);
  Eigen::Vector3d helper = Eigen::Vector3d::Zero();
  helper[least] = 1.0;
  const Eigen::Vector3d e2 = (helper - helper.dot(e1) * e1).normalized();
  rotation_.col(0) = e1;
  rotation_.col(1) = e2;
  rotation_.col(2) = e1.cross(e2);
}

bool ProlateHyperspheroid::contains(const Eigen::Vector3d& x) const {
  return (x - a_).norm() + (x - b_).norm() <= c_;
}

double ProlateHyperspheroid::measure() const { return 4.0 / 3.0 * M_PI * r1_ * r2_ * r2_; }

Eigen::Vector3d ProlateHyperspheroid::sample(Rng& rng) const {
  Eigen::Vector3d u;
  do {
    u = Eigen::Vector3d(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0));
  } while (u.squaredNorm() > 1.0);
  return rotation_ * Eigen::Vector3d(r1_ * u.x(), r2_ * u.y(), r2_ * u.z()) + centre_;
}

GuidedLocalSubsets::GuidedLocalSubsets(const Eigen::Vector3d& start, const Eigen::Vector3d& goal,
                                       const Eigen::Vector3d& beacon, double cost_to_beacon, double best_cost)
    : to_start_(start, beacon, cost_to_beacon),
      to_goal_(beacon, goal, best_cost - cost_to_beacon),
      m_start_(to_start_.measure()),
      m_goal_(to_goal_.measure()) {}

const ProlateHyperspheroid& GuidedLocalSubsets::pick(Rng& rng) const {
  return rng.uniform01() * (m_start_ + m_goal_) < m_start_ ? to_start_ : to_goal_;
}

}  // namespace miner::plan
