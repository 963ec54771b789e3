// The paper's front end and back end on a map of yours: the sGAN predicts the region a good
// path lies in (Alg. 1 lines 2-3), MINER RRT* samples it (Alg. 1), MINCO smooths the path.
//
//   plan_with_sgan MAP.json [x0 y0 z0 x1 y1 z1 radius]   (default: the map's stored query)
#include <cstdio>
#include <cstdlib>

#include "miner/core/error.hpp"
#include "miner/heuristic/region_filter.hpp"
#include "miner/heuristic/sgan.hpp"
#include "miner/plan/rrt_star.hpp"
#include "miner/traj/minco.hpp"
#include "miner/traj/trapezoidal_allocation.hpp"
#include "miner/world/map.hpp"

int main(int argc, char** argv) {
  if (argc != 2 && argc != 9) {
    std::fprintf(stderr, "usage: plan_with_sgan MAP.json [x0 y0 z0 x1 y1 z1 radius]\n");
    return 2;
  }
  try {
    // The map outlives the problem: PlanningProblem refers to it (a temporary does not compile).
    const miner::world::Map map = miner::world::Map::load(argv[1]);
    Eigen::Vector3d start, goal;
    double radius = 0.0;
    if (argc == 9) {
      start = {std::atof(argv[2]), std::atof(argv[3]), std::atof(argv[4])};
      goal = {std::atof(argv[5]), std::atof(argv[6]), std::atof(argv[7])};
      radius = std::atof(argv[8]);
    } else if (map.query()) {
      start = map.query()->start;
      goal = map.query()->goal;
      radius = map.query()->robot_radius;
    } else {
      throw miner::Error(std::string(argv[1]) + ": has no query; give start, goal and radius");
    }
    // 1. The heuristic region: the shipped network (compiled into the library), filtered.
    const miner::heuristic::Sgan sgan = miner::heuristic::Sgan::builtin();
    const auto query = miner::heuristic::query_region(sgan, map, start, goal, radius, /*seed=*/1);
    std::printf("region: %zu cells, %.2f ms (encode %.2f, inference %.2f, filter %.2f)\n",
                query.region.cells().size(), query.encode_ms + query.inference_ms + query.filter_ms,
                query.encode_ms, query.inference_ms, query.filter_ms);
    // 2. MINER RRT* biased toward it.
    const auto problem = miner::plan::PlanningProblem::make(map, start, goal, radius);
    miner::plan::PlannerOptions options;
    options.planner = miner::plan::PlannerKind::kMiner;
    options.max_iterations = 5000;
    const miner::plan::PlanResult result = miner::plan::plan(problem, options, &query.region);
    if (!result.solved) {
      std::fprintf(stderr, "plan_with_sgan: no path: %s\n", result.reason.c_str());
      return 3;
    }
    std::printf("MINER RRT*: cost %.3f m after %zu iterations (first solution at %zu)\n", result.cost,
                result.iterations, result.first ? result.first->iteration : 0);
    // 3. A minimum-snap trajectory through the path.
    Eigen::MatrixX3d points(static_cast<Eigen::Index>(result.path.size()), 3);
    for (std::size_t i = 0; i < result.path.size(); ++i) points.row(static_cast<Eigen::Index>(i)) = result.path[i];
    const auto durations = miner::traj::trapezoidal_allocation(points, miner::traj::Limits{2.0, 1.0});
    const auto trajectory = miner::traj::solve_minco(miner::traj::rest_to_rest(4, points, durations));
    std::printf("trajectory: %d segments, %.2f s\n", trajectory.segments(), trajectory.total_duration());
  } catch (const miner::Error& e) {
    std::fprintf(stderr, "plan_with_sgan: %s\n", e.what());
    return 1;
  }
  return 0;
}
