#pragma once
/// \file
/// The L2 informed set of Informed RRT* (Gammell, Barfoot, Srinivasa 2018):
///   X_f = { x : |x - x_a| + |x - x_b| <= c },
/// a prolate hyperspheroid with foci x_a, x_b and transverse diameter c >= |x_b - x_a|,
/// sampled directly (REQ-PLAN-002). Guided RRT*'s local subsets (Scalise et al. 2023) are
/// sets of the same shape with a beacon as one focus.

#include <Eigen/Core>

namespace miner {
class Rng;
}

namespace miner::plan {

class ProlateHyperspheroid {
 public:
  /// Requires c >= |b - a| (a c below that is raised to it: the set is then the segment).
  ProlateHyperspheroid(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double c);

  bool contains(const Eigen::Vector3d& x) const;
  /// Volume (4/3) pi r1 r2^2 with r1 = c/2, r2 = sqrt(c^2 - c_min^2)/2.
  double measure() const;
  /// Uniform on the set: x = C L x_ball + centre with x_ball uniform in the unit ball
  /// (by rejection from the cube), L = diag(r1, r2, r2), C a rotation taking e1 to the
  /// focal axis (any completion of the axis works: the set is symmetric about it).
  Eigen::Vector3d sample(Rng& rng) const;

  double transverse_diameter() const { return c_; }

 private:
  Eigen::Vector3d a_, b_, centre_;
  double c_;
  double r1_, r2_;
  Eigen::Matrix3d rotation_;
};

}  // namespace miner::plan
