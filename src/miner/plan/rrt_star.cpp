#include "miner/plan/rrt_star.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include "miner/core/error.hpp"
#include "miner/core/rng.hpp"
#include "miner/core/stopwatch.hpp"
#include "miner/core/text.hpp"
#include "miner/plan/heuristic_region.hpp"
#include "miner/plan/informed_set.hpp"
#include "miner/plan/kd_tree.hpp"
#include "miner/world/map.hpp"

namespace miner::plan {

namespace {

constexpr double kDimension = 3.0;
/// zeta_3: volume of the unit ball in R^3.
constexpr double kUnitBallVolume = 4.0 / 3.0 * M_PI;
/// A rewire must lower a cost by more than this (relative to the cost) to happen, so
/// that rounding noise never flips parents back and forth.
constexpr double kRewireRelativeMargin = 1e-12;
/// Rejection tries for a sample of (informed set) x (map bounds) before falling back
/// to a uniform sample of the map (which keeps completeness and never loops forever).
constexpr int kMaxRejectionTries = 64;
/// Safeguard (REQ-PLAN-020): a region whose cells hold at least this share of the best
/// path's length has guided the solution and keeps the full mu_1; below it the trust falls
/// in proportion. Not 1: a good region's solution still cuts corners between cells and
/// leaves H near x_init and x_goal (the A*-dilated region keeps tau = 1 in 195 of 200
/// door-map trials at 0.75), while a region that merely holds x_init's surroundings holds
/// a quarter of the path or less.
constexpr double kTrustedPathFraction = 0.75;
/// Safeguard: a region whose cells do not chain x_init's cell to x_goal's (H disconnected
/// on the grid) cannot lead the tree to the goal by itself; its patience is k_0 / 3.
constexpr double kDisconnectedPatience = 3.0;

using Clock = std::chrono::steady_clock;

void require_probability(double p, const std::string& name, bool below_one) {
  if (!(p >= 0.0 && (below_one ? p < 1.0 : p <= 1.0))) {
    std::ostringstream s;
    s << name << ": must be in [0, 1" << (below_one ? ")" : "]") << ", got " << exact_number(p);
    throw Error(s.str());
  }
}

/// One RRT* run (Karaman & Frazzoli 2011, Alg. 6) with a pluggable sampler.
class RrtStar {
 public:
  RrtStar(const PlanningProblem& problem, const PlannerOptions& options, const HeuristicRegion* region)
      : problem_(problem), map_(*problem.map), options_(options), region_(region),
        rng_(options.seed, options.stream) {
    eta_ = resolved_steer_step(options, map_);
    goal_radius_ = resolved_goal_radius(options, map_);
    if (options.planner == PlannerKind::kMiner && options.safeguard) {
      goal_hops_ = region->hops_to(problem.goal);
      const long c = region->cell_at(problem.start);
      region_connected_ = c >= 0 && goal_hops_[static_cast<std::size_t>(c)] >= 0;
    }
    gamma_ = options.rewire_factor * std::pow(2.0 * (1.0 + 1.0 / kDimension), 1.0 / kDimension) *
             std::pow(problem.sampled_volume / kUnitBallVolume, 1.0 / kDimension);
  }

  PlanResult run();

 private:
  Eigen::Vector3d sample();
  Eigen::Vector3d sample_uniform() {
    const world::Box& b = map_.bounds();
    return {rng_.uniform(b.min.x(), b.max.x()), rng_.uniform(b.min.y(), b.max.y()),
            rng_.uniform(b.min.z(), b.max.z())};
  }
  /// Uniform on set ∩ bounds by rejection, falling back to Uniform(Map).
  Eigen::Vector3d sample_in(const ProlateHyperspheroid& set) {
    const world::Box& b = map_.bounds();
    const bool set_smaller = set.measure() < b.volume();
    for (int t = 0; t < kMaxRejectionTries; ++t) {
      const Eigen::Vector3d x = set_smaller ? set.sample(rng_) : sample_uniform();
      if (set_smaller ? b.contains(x) : set.contains(x)) return x;
    }
    return sample_uniform();
  }
  Eigen::Vector3d sample_informed() {
    return sample_in(ProlateHyperspheroid(problem_.start, problem_.goal, best_cost_));
  }
  Eigen::Vector3d sample_guided_local();
  /// tau_t of REQ-PLAN-020, set before iteration t's sample.
  void update_trust(std::size_t t);

  double rewire_radius() const {
    const double n = static_cast<double>(positions_.size() + 1);
    return std::min(eta_, gamma_ * std::pow(std::log(n) / n, 1.0 / kDimension));
  }
  bool free(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
    return map_.segment_free(a, b, problem_.robot_radius);
  }
  void set_parent(std::size_t v, std::size_t parent, double cost);
  void propagate_cost(std::size_t v);
  void update_best(std::size_t iteration, Clock::time_point t0);
  std::vector<Eigen::Vector3d> path_to(std::size_t v) const;

  const PlanningProblem& problem_;
  const world::Map& map_;
  const PlannerOptions& options_;
  const HeuristicRegion* region_;
  Rng rng_;
  double eta_ = 0.0, goal_radius_ = 0.0, gamma_ = 0.0;

  KdTree tree_;
  std::vector<Eigen::Vector3d> positions_;
  std::vector<long> parent_;
  std::vector<double> cost_;
  std::vector<std::vector<std::uint32_t>> children_;
  std::vector<std::size_t> goal_vertices_;

  double best_cost_ = std::numeric_limits<double>::infinity();
  long best_vertex_ = -1;
  // Guided RRT* beacons: interior vertices of the current solution, with cost-to-come.
  std::vector<std::pair<Eigen::Vector3d, double>> beacons_;
  // MINER safeguard (REQ-PLAN-020): the trust from the best path, and tau_t itself.
  double path_trust_ = 1.0;
  double trust_ = 1.0;
  // Progress along H: hops through H's cells from each cell to x_goal's cell, the fewest
  // reached by a vertex so far, and the iteration that reached it.
  std::vector<int> goal_hops_;
  int best_hops_ = std::numeric_limits<int>::max();
  bool region_connected_ = true;
  std::size_t progress_iteration_ = 0;
  void note_progress(const Eigen::Vector3d& x, std::size_t iteration) {
    if (goal_hops_.empty()) return;
    const long c = region_->cell_at(x);
    const int h = c >= 0 ? goal_hops_[static_cast<std::size_t>(c)] : -1;
    if (h >= 0 && h < best_hops_) {
      best_hops_ = h;
      progress_iteration_ = iteration;
    }
  }

  PlanResult result_;
  // Scratch buffers reused every iteration.
  std::vector<std::size_t> near_;
  std::vector<std::pair<double, std::size_t>> candidates_;
  std::vector<signed char> checked_;  // per candidate: -1 unknown, 0 blocked, 1 free
  std::vector<std::uint32_t> propagate_stack_;
};

Eigen::Vector3d RrtStar::sample() {
  if (options_.goal_bias > 0.0 && rng_.uniform01() < options_.goal_bias) return problem_.goal;
  const bool solved = best_vertex_ >= 0;
  switch (options_.planner) {
    case PlannerKind::kRrtStar:
      return sample_uniform();
    case PlannerKind::kInformed:
      return solved ? sample_informed() : sample_uniform();
    case PlannerKind::kGuided:
      if (!solved) return sample_uniform();
      if (!beacons_.empty() && rng_.uniform01() < options_.guided_local_fraction) {
        return sample_guided_local();
      }
      return sample_informed();
    case PlannerKind::kMiner: {
      const double mu = (solved ? options_.mu_1 : options_.mu_2) * trust_;
      if (rng_.uniform01() < mu) {
        ++result_.region_samples;
        return region_->sample(rng_);
      }
      return sample_uniform();
    }
  }
  return sample_uniform();
}

void RrtStar::update_trust(std::size_t t) {
  if (options_.planner != PlannerKind::kMiner || !options_.safeguard) return;
  // Before the first solution: k_0 / (t - t_p) once the tree has gone k_0 iterations
  // without a vertex fewer H-hops from x_goal than any before (t_p: the last such
  // iteration); after it: the share of the best path that H holds.
  const double stalled = static_cast<double>(t - progress_iteration_);
  const double k0 =
      static_cast<double>(options_.safeguard_iterations) / (region_connected_ ? 1.0 : kDisconnectedPatience);
  trust_ = best_vertex_ >= 0 ? path_trust_ : std::min(1.0, k0 / stalled);
}

Eigen::Vector3d RrtStar::sample_guided_local() {
  const auto& [b, g] = beacons_[rng_.uniform_index(beacons_.size())];
  const GuidedLocalSubsets local(problem_.start, problem_.goal, b, g, best_cost_);
  if (!local.has_volume()) return sample_informed();
  ++result_.guided_local_samples;
  return sample_in(local.pick(rng_));
}

void RrtStar::set_parent(std::size_t v, std::size_t parent, double cost) {
  const long old = parent_[v];
  if (old >= 0) {
    auto& siblings = children_[static_cast<std::size_t>(old)];
    siblings.erase(std::find(siblings.begin(), siblings.end(), static_cast<std::uint32_t>(v)));
  }
  parent_[v] = static_cast<long>(parent);
  children_[parent].push_back(static_cast<std::uint32_t>(v));
  cost_[v] = cost;
}

void RrtStar::propagate_cost(std::size_t v) {
  auto& stack = propagate_stack_;
  stack.assign(children_[v].begin(), children_[v].end());
  while (!stack.empty()) {
    const std::uint32_t c = stack.back();
    stack.pop_back();
    const auto p = static_cast<std::size_t>(parent_[c]);
    cost_[c] = cost_[p] + (positions_[c] - positions_[p]).norm();
    stack.insert(stack.end(), children_[c].begin(), children_[c].end());
  }
}

std::vector<Eigen::Vector3d> RrtStar::path_to(std::size_t v) const {
  std::vector<Eigen::Vector3d> path;
  for (long at = static_cast<long>(v); at >= 0; at = parent_[static_cast<std::size_t>(at)]) {
    path.push_back(positions_[static_cast<std::size_t>(at)]);
  }
  std::reverse(path.begin(), path.end());
  if ((path.back() - problem_.goal).norm() > 0.0) path.push_back(problem_.goal);
  return path;
}

void RrtStar::update_best(std::size_t iteration, Clock::time_point t0) {
  double best = std::numeric_limits<double>::infinity();
  long vertex = -1;
  for (std::size_t v : goal_vertices_) {
    const double c = cost_[v] + (positions_[v] - problem_.goal).norm();
    if (c < best) {
      best = c;
      vertex = static_cast<long>(v);
    }
  }
  if (vertex < 0 || !(best < best_cost_)) return;
  best_cost_ = best;
  best_vertex_ = vertex;
  const StageRecord record{iteration, positions_.size() - 1, best, elapsed_ms(t0)};
  if (!result_.first) result_.first = record;
  result_.improvements.push_back(record);
  if (options_.target_cost && !result_.target && best <= *options_.target_cost) result_.target = record;
  if (options_.planner == PlannerKind::kMiner && options_.safeguard) {
    const double inside = region_->length_fraction_inside(path_to(static_cast<std::size_t>(vertex)));
    path_trust_ = std::min(1.0, inside / kTrustedPathFraction);
  }
  if (options_.planner == PlannerKind::kGuided) {
    beacons_.clear();
    const auto path = path_to(static_cast<std::size_t>(vertex));
    double g = 0.0;
    for (std::size_t i = 1; i + 1 < path.size(); ++i) {
      g += (path[i] - path[i - 1]).norm();
      beacons_.emplace_back(path[i], g);
    }
    result_.guided_beacons.clear();
    for (const auto& beacon : beacons_) result_.guided_beacons.push_back(beacon.first);
  }
}

PlanResult RrtStar::run() {
  const Clock::time_point t0 = Clock::now();
  result_.planner = options_.planner;
  result_.steer_step = eta_;
  result_.goal_radius = goal_radius_;

  positions_.push_back(problem_.start);
  parent_.push_back(-1);
  cost_.push_back(0.0);
  children_.emplace_back();
  tree_.insert(problem_.start);
  note_progress(problem_.start, 0);
  if ((problem_.start - problem_.goal).norm() <= goal_radius_ && free(problem_.start, problem_.goal)) {
    goal_vertices_.push_back(0);
  }
  update_best(0, t0);

  std::size_t iteration = 0;
  while (iteration < options_.max_iterations) {
    if (options_.stop_at_first && result_.first) break;
    if (result_.target) break;
    // No path is shorter than the straight line ||x_goal - x_init||: a path of that cost (start
    // within the goal radius, start == goal included) is optimal, and more iterations would only
    // grow the tree (issue 20, third campaign: 20 000 iterations after a cost-0 answer).
    if (best_cost_ <= (problem_.goal - problem_.start).norm()) break;
    ++iteration;
    if (options_.poll && iteration % kPollIterations == 0) options_.poll();
    update_trust(iteration);
    const Eigen::Vector3d x_rand = sample();
    const std::size_t nearest = tree_.nearest(x_rand);
    const Eigen::Vector3d& x_nearest = positions_[nearest];
    // Steer: move from x_nearest toward x_rand by at most eta.
    const Eigen::Vector3d delta = x_rand - x_nearest;
    const double dist = delta.norm();
    if (dist == 0.0) continue;
    const Eigen::Vector3d x_new = dist <= eta_ ? x_rand : Eigen::Vector3d(x_nearest + delta * (eta_ / dist));
    if (!free(x_nearest, x_new)) continue;

    // Extend: the parent minimising cost-to-come among X_near (x_nearest always qualifies).
    tree_.within(x_new, rewire_radius(), near_);
    candidates_.clear();
    for (std::size_t v : near_) candidates_.emplace_back(cost_[v] + (positions_[v] - x_new).norm(), v);
    std::sort(candidates_.begin(), candidates_.end());
    checked_.assign(candidates_.size(), -1);
    std::size_t parent = nearest;
    double cost_new = cost_[nearest] + (x_new - x_nearest).norm();
    for (std::size_t c = 0; c < candidates_.size(); ++c) {
      if (candidates_[c].first >= cost_new) break;
      const std::size_t v = candidates_[c].second;
      checked_[c] = free(positions_[v], x_new) ? 1 : 0;
      if (checked_[c]) {
        parent = v;
        cost_new = candidates_[c].first;
        break;
      }
    }
    const std::size_t v_new = positions_.size();
    positions_.push_back(x_new);
    parent_.push_back(-1);
    cost_.push_back(0.0);
    children_.emplace_back();
    tree_.insert(x_new);
    set_parent(v_new, parent, cost_new);
    note_progress(x_new, iteration);

    // Rewire: X_near vertices that x_new reaches more cheaply.
    for (std::size_t c = 0; c < candidates_.size(); ++c) {
      const std::size_t v = candidates_[c].second;
      if (v == parent) continue;
      const double via_new = cost_new + (positions_[v] - x_new).norm();
      if (!(via_new < cost_[v] * (1.0 - kRewireRelativeMargin))) continue;
      if (checked_[c] < 0) checked_[c] = free(x_new, positions_[v]) ? 1 : 0;
      if (!checked_[c]) continue;
      set_parent(v, v_new, via_new);
      propagate_cost(v);
    }
    if ((x_new - problem_.goal).norm() <= goal_radius_ && free(x_new, problem_.goal)) {
      goal_vertices_.push_back(v_new);
    }
    update_best(iteration, t0);
  }

  result_.iterations = iteration;
  result_.nodes = positions_.size() - 1;
  result_.region_trust = trust_;
  result_.time_ms = elapsed_ms(t0);
  if (best_vertex_ >= 0) {
    result_.solved = true;
    result_.path = path_to(static_cast<std::size_t>(best_vertex_));
    result_.cost = path_length(result_.path);
  } else {
    std::ostringstream s;
    s << "no path to the goal region (radius " << goal_radius_ << " m) within " << iteration
      << " iterations (" << result_.nodes << " vertices)";
    result_.reason = s.str();
  }
  if (options_.record_tree) {
    result_.tree_vertices = positions_;
    result_.tree_parents = parent_;
    result_.tree_costs = cost_;
  }
  return result_;
}

}  // namespace

double resolved_steer_step(const PlannerOptions& options, const world::Map& map) {
  const world::Box& b = map.bounds();
  return options.steer_step > 0.0 ? options.steer_step : 0.1 * (b.max - b.min).norm();
}

double resolved_goal_radius(const PlannerOptions& options, const world::Map& map) {
  return options.goal_radius > 0.0 ? options.goal_radius : 2.0 * map.resolution();
}

double path_length(const std::vector<Eigen::Vector3d>& path) {
  double length = 0.0;
  for (std::size_t i = 1; i < path.size(); ++i) length += (path[i] - path[i - 1]).norm();
  return length;
}

std::string planner_name(PlannerKind kind) {
  switch (kind) {
    case PlannerKind::kRrtStar: return "rrtstar";
    case PlannerKind::kInformed: return "informed";
    case PlannerKind::kGuided: return "guided";
    case PlannerKind::kMiner: return "miner";
  }
  return "?";
}

PlannerKind planner_from_name(const std::string& name) {
  for (PlannerKind k : all_planners()) {
    if (planner_name(k) == name) return k;
  }
  throw Error("unknown planner \"" + name + "\"; expected one of rrtstar, informed, guided, miner");
}

std::vector<PlannerKind> all_planners() {
  return {PlannerKind::kRrtStar, PlannerKind::kInformed, PlannerKind::kGuided, PlannerKind::kMiner};
}

void validate(const PlanningProblem& p) {
  if (p.map == nullptr) throw Error("plan: the problem has no map");
  // Twelfth campaign L5: a map moved into a container left an empty map behind (its bounds,
  // no obstacles), and the problem planned on it straight through a box.
  if (p.map->fingerprint() == 0) throw Error("plan: the problem's map was moved from (it has no obstacles left)");
  if (p.map_fingerprint != 0 && p.map_fingerprint != p.map->fingerprint())
    throw Error("plan: the problem's map changed since PlanningProblem::make (another map was assigned to it)");
  require_finite(p.start, "start");
  require_finite(p.goal, "goal");
  // The map format's range (REQ-WORLD-002): a radius above it is no quadrotor (issue 20,
  // ninth campaign P11: Python's plan took 10.5 m, which the CLI and every file refuse).
  world::check_robot_radius(p.robot_radius, "robot_radius");
  p.map->require_free(p.start, p.robot_radius, "start");
  p.map->require_free(p.goal, p.robot_radius, "goal");
  // Lemma 2's radius uses the sampled volume: it must be a volume (tenth campaign L11: 0 and
  // NaN planned with a rewiring radius of 0 and NaN).
  if (!(std::isfinite(p.sampled_volume) && p.sampled_volume > 0.0))
    throw Error("sampled_volume: must be a positive finite volume in m^3, got " + exact_number(p.sampled_volume));
}

PlanningProblem PlanningProblem::make(const world::Map& map, const Eigen::Vector3d& start,
                                      const Eigen::Vector3d& goal, double robot_radius) {
  PlanningProblem p;
  p.map = &map;
  p.start = start;
  p.goal = goal;
  p.robot_radius = robot_radius;
  p.sampled_volume = map.bounds().volume();
  p.map_fingerprint = map.fingerprint();
  validate(p);
  return p;
}

PlanResult plan(const PlanningProblem& problem, const PlannerOptions& options, const HeuristicRegion* region) {
  // The problem's fields are public: one filled by hand is checked like make()'s (tenth
  // campaign L11: a NaN radius "solved" with a vacuous collision check).
  validate(problem);
  // An int cast to the enum outside its four values planned as RRT* under a name of "?"
  // (tenth campaign recheck).
  if (static_cast<unsigned>(options.planner) > static_cast<unsigned>(PlannerKind::kMiner))
    throw Error("planner: " + std::to_string(static_cast<int>(options.planner)) +
                " is not a PlannerKind (rrtstar, informed, guided, miner)");
  require_probability(options.goal_bias, "goal_bias", true);
  require_probability(options.mu_1, "mu_1", true);
  require_probability(options.mu_2, "mu_2", true);
  require_probability(options.guided_local_fraction, "guided_local_fraction", false);
  require_finite(options.steer_step, "steer_step");
  require_finite(options.goal_radius, "goal_radius");
  // A step far below the map's cells moves nothing the collision checks resolve, and every new
  // vertex lands within the near radius of all the others: work grows with the square of the
  // iterations (issue 20, seventh campaign H1: --step 1e-6 took 5.6 s for 20 000 iterations).
  constexpr double kMinSteerStepCells = 0.1;
  // The bound is a product of decimals: 0.1 x 0.1 m is 0.010000000000000002, so a step of exactly
  // the documented 0.01 m was refused (ninth campaign C6). Rounding of that size is forgiven.
  constexpr double kStepRounding = 1e-12;
  if (options.steer_step > 0.0 &&
      options.steer_step < kMinSteerStepCells * problem.map->resolution() * (1.0 - kStepRounding)) {
    std::ostringstream os;
    os << "steer_step (--step, planner.step): " << options.steer_step << " m is below a tenth of the map's resolution "
       << problem.map->resolution() << " m: steps that short resolve nothing and make every vertex a neighbour of "
       << "every other (give at least " << kMinSteerStepCells * problem.map->resolution() << " m, or leave it out for the default)";
    throw Error(os.str());
  }
  if (!(options.rewire_factor >= 1.0 && std::isfinite(options.rewire_factor))) {
    throw Error("rewire_factor: must be a finite number >= 1 (Lemma 2's radius condition)");
  }
  if (options.max_iterations > kMaxIterations)
    throw Error("max_iterations: " + std::to_string(options.max_iterations) + " is above the largest budget " +
                std::to_string(kMaxIterations) + " (a run of minutes; see plan::kMaxIterations)");
  // A path's length is >= 0: a negative target could never be met and only hid a sign error
  // (tenth campaign recheck).
  if (options.target_cost && !(std::isfinite(*options.target_cost) && *options.target_cost >= 0.0))
    throw Error("target_cost: must be a finite path length >= 0 m, got " + exact_number(*options.target_cost));
  if (options.safeguard_iterations < 1) throw Error("safeguard_iterations: must be >= 1 (k_0 of the safeguard)");
  if (options.planner == PlannerKind::kMiner) {
    if (region == nullptr) throw Error("planner miner: needs a heuristic region");
    region->require_matches(*problem.map, "planner miner");
  }
  RrtStar planner(problem, options, region);
  return planner.run();
}

void add_setup_time(PlanResult& result, double ms) {
  if (!(std::isfinite(ms) && ms >= 0.0)) throw Error("setup time: must be a finite time >= 0 ms, got " + exact_number(ms));
  result.time_ms += ms;
  if (result.first) result.first->time_ms += ms;
  if (result.target) result.target->time_ms += ms;
}

}  // namespace miner::plan
