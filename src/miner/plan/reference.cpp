#include "miner/plan/reference.hpp"

#include "miner/world/astar.hpp"
#include "miner/world/map.hpp"
#include "miner/world/voxel_grid.hpp"

namespace miner::plan {

ReferencePath astar_reference(const PlanningProblem& problem) {
  const world::VoxelGrid grid(*problem.map, problem.robot_radius);
  const world::GridPath path = world::astar(*problem.map, grid, problem.start, problem.goal);
  return {path.points, path.cost};
}

HeuristicRegion astar_dilated_region(const PlanningProblem& problem, const ReferencePath& reference,
                                     const Eigen::Vector3i& dims, int dilation) {
  HeuristicRegion region = HeuristicRegion::from_path(problem.map->bounds(), dims, reference.points, dilation, "astar-dilated");
  region.set_map_fingerprint(problem.map->fingerprint());
  return region;
}

double straight_line_bound(const PlanningProblem& problem) { return (problem.goal - problem.start).norm(); }

}  // namespace miner::plan
