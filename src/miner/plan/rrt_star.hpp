#pragma once
/// \file
/// The RRT* family of the paper's front end (Sec. IV-A, Alg. 1): one tree with
/// Extend / Rewire (Karaman & Frazzoli 2011, Alg. 6) and four sampling policies
/// (REQ-PLAN-001..005):
///
///  - `rrtstar`:  Uniform(Map) [Karaman 2011].
///  - `informed`: Uniform(Map) until a solution of cost c_best exists, then uniform on the
///                L2 informed set {x : |x - x_init| + |x - x_goal| <= c_best} intersected
///                with the map [Gammell 2018].
///  - `guided`:   as `informed`, but a fraction `guided_local_fraction` of the samples after
///                the first solution is drawn from the local subsets of a beacon b on the
///                current solution (GuILD, Scalise et al. 2023): {x : |x - x_init| +
///                |x - b| <= g(b)} and {x : |x - b| + |x - x_goal| <= c_best - g(b)}, chosen
///                in proportion to their volumes; beacons are the solution's interior vertices.
///  - `miner`:    Alg. 1 Lines 5-17: Nonuniform(H) with probability mu_2 before the first
///                solution and mu_1 after it, else Uniform(Map). mu_1, mu_2 < 1, which is what
///                keeps Lemma 1 (probabilistic completeness) whatever H is. With the
///                safeguard (default, REQ-PLAN-020) mu is scaled online by a trust
///                tau_t in [0, 1] that falls when H proves poor, so sampling moves toward
///                Uniform(Map); tau_t <= 1 keeps Lemma 1.
///
/// Every policy first draws x_goal itself with probability `goal_bias` (as OMPL does).
///
/// Extend uses the rewiring radius of Alg. 1 Line 21, r_n = min(eta, gamma (log n / n)^(1/d)),
/// d = 3, gamma = rewire_factor * (2 (1 + 1/d))^(1/d) (M(X) / zeta_d)^(1/d) (the paper's
/// Lemma 2 condition with the (log n / n)^(1/d) factor the paper omits; Solovey et al. 2020
/// show the constant must be larger than Karaman & Frazzoli's for RRT*, hence rewire_factor
/// > 1, 1.1 by default as in OMPL). M(X) is the volume of the map's bounds, the set every
/// planner samples, as OMPL takes it: it is >= M(X_free), so the condition holds with room,
/// and on a map half full of obstacles the M(X_free) constant needed ~3x OMPL's iterations
/// (REQ-PLAN-021). eta is the steering step.
///
/// The goal region is X_goal = {x : |x - x_goal| <= goal_radius}. A vertex in X_goal whose
/// straight segment to x_goal is collision-free is a goal vertex; a solution is the tree
/// path to a goal vertex followed by x_goal itself, so every returned path ends exactly at
/// the goal and its cost is its Euclidean length.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace miner::world {
class Map;
}

namespace miner::plan {

class HeuristicRegion;

enum class PlannerKind { kRrtStar, kInformed, kGuided, kMiner };

/// "rrtstar", "informed", "guided", "miner".
std::string planner_name(PlannerKind kind);
/// Inverse of planner_name; throws miner::Error listing the valid names.
PlannerKind planner_from_name(const std::string& name);
/// All four, in the order above.
std::vector<PlannerKind> all_planners();

/// The largest iteration budget a run takes: 10^6 iterations grow a tree of ~100 MB and take
/// about 40 s on a 10 m map on one core (the near sets grow as log n); 10^7 took minutes (issue
/// 20, seventh campaign H2). Five times the largest default budget (a benchmark's 2 x 10^5).
inline constexpr std::size_t kMaxIterations = 1000000;

/// Parameters of a planning run, with their defaults (REQ-PLAN-007).
struct PlannerOptions {
  PlannerKind planner = PlannerKind::kRrtStar;
  std::uint64_t seed = 1;
  std::uint64_t stream = 0;          ///< Rng stream (the trial number in a campaign)
  std::size_t max_iterations = 20000;  ///< budget: Alg. 1's N
  double steer_step = 0.0;   ///< eta (m); <= 0: 0.1 x the diagonal of the map's bounds
  double goal_radius = 0.0;  ///< r of X_goal (m); <= 0: 2 x the map's resolution
  double goal_bias = 0.05;   ///< probability of sampling x_goal itself
  double rewire_factor = 1.1;
  double mu_1 = 0.5;         ///< miner: P(sample H) after the first solution
  double mu_2 = 0.9;         ///< miner: P(sample H) before the first solution
  double guided_local_fraction = 0.5;  ///< guided: P(local subset) after the first solution
  /// miner: scale mu by the region's trust tau_t (REQ-PLAN-020); false: the paper's fixed mu.
  bool safeguard = true;
  /// miner safeguard: k_0, the patience before the first solution: after k_0 iterations
  /// without the tree getting closer to x_goal through H, tau_t = k_0 / (iterations stalled).
  std::size_t safeguard_iterations = 300;
  std::optional<double> target_cost;   ///< stop as soon as the cost is <= this
  bool stop_at_first = false;          ///< stop at the first solution (Alg. 1 Line 24)
  bool record_tree = false;            ///< keep the final tree in the result
  /// Called every kPollIterations iterations on the planning thread, if set; it may throw to
  /// abandon the run (the exception leaves plan()). The Python module raises KeyboardInterrupt
  /// through it (eleventh campaign P1: Ctrl-C waited for the whole budget, ~40 s at 10^6).
  std::function<void()> poll;
};

/// How often PlannerOptions::poll is called: ~1024 iterations are tens of milliseconds.
inline constexpr std::size_t kPollIterations = 1024;

/// eta actually used: options.steer_step, or 0.1 x the diagonal of the map's bounds.
double resolved_steer_step(const PlannerOptions& options, const world::Map& map);
/// r of X_goal actually used: options.goal_radius, or 2 x the map's resolution.
double resolved_goal_radius(const PlannerOptions& options, const world::Map& map);

/// Euclidean length of a polyline (the cost of every path the front end reports).
double path_length(const std::vector<Eigen::Vector3d>& path);

/// A planning query after validation (REQ-PLAN-008): start and goal inside the bounds and
/// at least robot_radius from every obstacle.
struct PlanningProblem {
  const world::Map* map = nullptr;
  Eigen::Vector3d start;
  Eigen::Vector3d goal;
  double robot_radius = 0.0;
  /// M(X) of the rewiring radius: the volume of the map's bounds, the set every planner
  /// samples (REQ-PLAN-021).
  double sampled_volume = 0.0;
  /// map->fingerprint() when make() built the problem (0 for one filled by hand): plan()
  /// refuses a map that has since been moved from or assigned another map.
  std::uint64_t map_fingerprint = 0;

  /// Throws miner::Error naming the fault (start/goal out of bounds or in collision). The
  /// problem refers to `map`, which the caller keeps alive and unchanged while the problem is
  /// used.
  static PlanningProblem make(const world::Map& map, const Eigen::Vector3d& start,
                              const Eigen::Vector3d& goal, double robot_radius);
  /// A temporary map would dangle: `make(Map::load(path), ...)` does not compile.
  static PlanningProblem make(world::Map&& map, const Eigen::Vector3d& start, const Eigen::Vector3d& goal,
                              double robot_radius) = delete;
};

/// The checks of PlanningProblem::make on a problem however it was filled (plan() calls it):
/// a map, finite ends free at a robot radius in range, a positive finite sampled volume.
/// Throws miner::Error naming the field.
void validate(const PlanningProblem& problem);

/// When a stage (first solution, target cost) was reached.
struct StageRecord {
  std::size_t iteration = 0;  ///< 1-based iteration that reached it
  std::size_t nodes = 0;      ///< vertices added to the tree by then (x_init not counted)
  double cost = 0.0;
  double time_ms = 0.0;       ///< wall clock since plan() started (not deterministic)
};

struct PlanResult {
  PlannerKind planner = PlannerKind::kRrtStar;
  bool solved = false;
  std::string reason;  ///< why not solved (empty if solved)
  std::vector<Eigen::Vector3d> path;  ///< x_init, ..., x_goal (the one point x_init when start == goal, cost 0)
  double cost = 0.0;                  ///< Euclidean length of path
  std::size_t iterations = 0;
  std::size_t nodes = 0;
  std::optional<StageRecord> first;
  std::optional<StageRecord> target;
  std::vector<StageRecord> improvements;  ///< every time the best cost dropped
  double time_ms = 0.0;
  /// miner: samples drawn from H, and the trust tau of the last iteration (1 without the
  /// safeguard or for the other planners).
  std::size_t region_samples = 0;
  /// guided: samples drawn from a beacon's local subsets (REQ-PLAN-003).
  std::size_t guided_local_samples = 0;
  /// guided: the beacons of the last improvement, the interior vertices of that solution (never
  /// x_init or the vertex in the goal region), in path order.
  std::vector<Eigen::Vector3d> guided_beacons;
  double region_trust = 1.0;
  double steer_step = 0.0;   ///< the eta and r actually used (defaults resolved)
  double goal_radius = 0.0;
  /// The final tree when options.record_tree: vertex positions, parent indices (-1: root)
  /// and costs-to-come.
  std::vector<Eigen::Vector3d> tree_vertices;
  std::vector<long> tree_parents;
  std::vector<double> tree_costs;  ///< cost-to-come of each vertex
};

/// Runs the planner for at most options.max_iterations iterations. `region` is required
/// for PlannerKind::kMiner (and must match the map, REQ-PLAN-008) and ignored otherwise.
/// Throws miner::Error for invalid options; an unsolved query is a result with
/// solved == false and a reason, never an exception or a hang.
PlanResult plan(const PlanningProblem& problem, const PlannerOptions& options,
                const HeuristicRegion* region = nullptr);

/// Counts `ms` of work done before plan() for this query (e.g. computing the heuristic
/// region) in the result's total time and in its first-solution and target stages, so
/// they read as end-to-end times. The improvements list keeps plan()'s own clock.
void add_setup_time(PlanResult& result, double ms);

}  // namespace miner::plan
