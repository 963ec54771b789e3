#include "miner/heuristic/strict_quality.hpp"

#include <cstdint>
#include <vector>

#include "miner/plan/heuristic_region.hpp"
#include "miner/world/map.hpp"
#include "miner/world/voxel_grid.hpp"

namespace miner::heuristic {

StrictQuality strict_quality(const world::Map& map, const world::VoxelGrid& grid, const plan::HeuristicRegion& region,
                             const Eigen::Vector3d& start, const Eigen::Vector3d& goal) {
  StrictQuality q;
  // passable[v]: voxel v is free and its centre lies in H.
  std::vector<std::uint8_t> passable(grid.cell_count(), 0);
  std::size_t unsafe = 0;
  for (std::size_t v = 0; v < grid.cell_count(); ++v) {
    const Eigen::Vector3d centre = grid.cell_center(v);
    if (!region.contains(centre)) continue;
    ++q.voxels;
    if (!map.is_free(centre, grid.robot_radius())) ++unsafe;
    if (!grid.occupied(v)) passable[v] = 1;
  }
  q.unsafe_fraction = q.voxels > 0 ? static_cast<double>(unsafe) / static_cast<double>(q.voxels) : 1.0;
  q.safe = q.voxels > 0 && q.unsafe_fraction <= kStrictUnsafeFraction;

  const auto a = grid.cell_of(start), b = grid.cell_of(goal);
  if (!a || !b) return q;
  const std::size_t from = grid.index(*a), to = grid.index(*b);
  if (!passable[from] || !passable[to]) return q;
  std::vector<std::size_t> queue{from};
  passable[from] = 2;  // visited
  const Eigen::Vector3i dims = grid.dims();
  for (std::size_t head = 0; head < queue.size() && !q.connected; ++head) {
    const Eigen::Vector3i c = grid.coords(queue[head]);
    for (int axis = 0; axis < 3; ++axis)
      for (int step : {-1, 1}) {
        Eigen::Vector3i n = c;
        n[axis] += step;
        if (n[axis] < 0 || n[axis] >= dims[axis]) continue;
        const std::size_t v = grid.index(n);
        if (passable[v] != 1) continue;
        passable[v] = 2;
        if (v == to) q.connected = true;
        queue.push_back(v);
      }
  }
  return q;
}

}  // namespace miner::heuristic
