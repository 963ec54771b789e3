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

/// Guided RRT*'s local subsets of a beacon b (REQ-PLAN-003; Scalise et al. 2023, GuILD): with
/// g the cost-to-come of b along the current solution of cost c_best,
///   L_start = {x : |x - x_start| + |x - b| <= g},   L_goal = {x : |x - b| + |x - x_goal| <= c_best - g},
/// one of which pick() chooses in proportion to their volumes, P(L_start) = m_s / (m_s + m_g).
class GuidedLocalSubsets {
 public:
  GuidedLocalSubsets(const Eigen::Vector3d& start, const Eigen::Vector3d& goal, const Eigen::Vector3d& beacon,
                     double cost_to_beacon, double best_cost);
  const ProlateHyperspheroid& to_start() const { return to_start_; }
  const ProlateHyperspheroid& to_goal() const { return to_goal_; }
  /// m_s + m_g > 0 (else there is nothing local to sample: the solution is a straight line).
  bool has_volume() const { return m_start_ + m_goal_ > 0.0; }
  double start_share() const { return m_start_ / (m_start_ + m_goal_); }
  /// L_start with probability start_share(), else L_goal (one uniform draw).
  const ProlateHyperspheroid& pick(Rng& rng) const;

 private:
  ProlateHyperspheroid to_start_, to_goal_;
  double m_start_, m_goal_;
};

}  // namespace miner::plan
