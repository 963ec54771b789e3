#include "miner/heuristic/strict_quality.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "miner/plan/heuristic_region.hpp"
#include "miner/world/astar.hpp"
#include "miner/world/map.hpp"
#include "miner/world/voxel_grid.hpp"

namespace miner::heuristic {

StrictQuality strict_quality(const world::Map& map, const world::VoxelGrid& grid, const plan::HeuristicRegion& region,
                             const Eigen::Vector3d& start, const Eigen::Vector3d& goal) {
  StrictQuality q;
  // passable[v]: voxel v is free and its centre lies in H. Only the voxels under H's cells
  // are visited (H is a few per cent of the map), each once: a voxel belongs to the cell
  // holding its centre.
  std::vector<std::uint8_t> passable(grid.cell_count(), 0);
  std::size_t unsafe = 0;
  const Eigen::Vector3i dims = grid.dims();
  for (const std::size_t cell : region.cells()) {
    const world::Box box = region.cell_box(cell);
    Eigen::Vector3i lo, hi;
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::max(0, static_cast<int>(std::floor((box.min[a] - grid.origin()[a]) / grid.resolution())));
      hi[a] = std::min(dims[a] - 1, static_cast<int>(std::floor((box.max[a] - grid.origin()[a]) / grid.resolution())));
    }
    for (int k = lo.z(); k <= hi.z(); ++k)
      for (int j = lo.y(); j <= hi.y(); ++j)
        for (int i = lo.x(); i <= hi.x(); ++i) {
          const Eigen::Vector3d centre = grid.cell_center(Eigen::Vector3i(i, j, k));
          if (region.cell_at(centre) != static_cast<long>(cell)) continue;
          ++q.voxels;
          if (!map.is_free(centre, grid.robot_radius())) ++unsafe;
          if (!grid.occupied(Eigen::Vector3i(i, j, k))) passable[grid.index(i, j, k)] = 1;
        }
  }
  q.unsafe_fraction = q.voxels > 0 ? static_cast<double>(unsafe) / static_cast<double>(q.voxels) : 1.0;
  q.safe = q.voxels > 0 && q.unsafe_fraction <= kStrictUnsafeFraction;

  const auto a = grid.cell_of(start), b = grid.cell_of(goal);
  if (!a || !b) return q;
  const std::size_t from = grid.index(*a), to = grid.index(*b);
  if (!passable[from] || !passable[to]) return q;
  // A*'s own graph (world::grid_moves): 26 neighbours, a diagonal step only where every cell
  // of the block it crosses is free. The step's segment runs between the two voxel centres and
  // so stays inside those two voxels, both in H; the block's other voxels need only be free.
  const std::array<world::GridMove, 26> moves = world::grid_moves(dims);
  std::vector<std::size_t> queue{from};
  passable[from] = 2;  // visited
  for (std::size_t head = 0; head < queue.size() && !q.connected; ++head) {
    const std::size_t cur = queue[head];
    const Eigen::Vector3i c = grid.coords(cur);
    for (const world::GridMove& m : moves) {
      const Eigen::Vector3i n = c + Eigen::Vector3i(m.dx, m.dy, m.dz);
      if ((n.array() < 0).any() || (n.array() >= dims.array()).any()) continue;
      const std::size_t v = grid.index(n);
      if (passable[v] != 1) continue;
      bool block_free = true;
      for (int w = 0; w < m.n_between && block_free; ++w)
        block_free = !grid.occupied(static_cast<std::size_t>(static_cast<std::ptrdiff_t>(cur) + m.between[static_cast<std::size_t>(w)]));
      if (!block_free) continue;
      passable[v] = 2;
      if (v == to) q.connected = true;
      queue.push_back(v);
    }
  }
  return q;
}

}  // namespace miner::heuristic
