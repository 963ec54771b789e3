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
  // holding its centre. Which cell that is depends on each axis alone (HeuristicRegion::
  // cell_at floors each coordinate), so the voxels of cell column c along axis a are one
  // run [first[a][c], last[a][c]], found once per axis with cell_at itself (the same
  // arithmetic, so the same answer at every boundary), not once per voxel.
  std::vector<std::uint8_t> passable(grid.cell_count(), 0);
  std::size_t unsafe = 0;
  const Eigen::Vector3i dims = grid.dims();
  const Eigen::Vector3i cells = region.dims();
  std::array<std::vector<int>, 3> first, last;
  for (int a = 0; a < 3; ++a) {
    first[static_cast<std::size_t>(a)].assign(static_cast<std::size_t>(cells[a]), 0);
    last[static_cast<std::size_t>(a)].assign(static_cast<std::size_t>(cells[a]), -1);
    Eigen::Vector3d p = region.bounds().min;
    for (int i = 0; i < dims[a]; ++i) {
      Eigen::Vector3i v = Eigen::Vector3i::Zero();
      v[a] = i;
      p[a] = grid.cell_center(v)[a];
      const long c = region.cell_at(p);
      if (c < 0) continue;  // a voxel centre outside H's bounds belongs to no cell
      const int column = region.coords(static_cast<std::size_t>(c))[a];
      auto& f = first[static_cast<std::size_t>(a)][static_cast<std::size_t>(column)];
      auto& l = last[static_cast<std::size_t>(a)][static_cast<std::size_t>(column)];
      if (l < f) f = i;
      l = i;
    }
  }
  const std::size_t nx = static_cast<std::size_t>(dims.x()), nxy = nx * static_cast<std::size_t>(dims.y());
  const double radius = grid.robot_radius();
  for (const std::size_t cell : region.cells()) {
    const Eigen::Vector3i c = region.coords(cell);
    const int i0 = first[0][static_cast<std::size_t>(c.x())], i1 = last[0][static_cast<std::size_t>(c.x())];
    const int j0 = first[1][static_cast<std::size_t>(c.y())], j1 = last[1][static_cast<std::size_t>(c.y())];
    const int k0 = first[2][static_cast<std::size_t>(c.z())], k1 = last[2][static_cast<std::size_t>(c.z())];
    for (int k = k0; k <= k1; ++k)
      for (int j = j0; j <= j1; ++j) {
        std::size_t v = static_cast<std::size_t>(k) * nxy + static_cast<std::size_t>(j) * nx + static_cast<std::size_t>(i0);
        for (int i = i0; i <= i1; ++i, ++v) {
          ++q.voxels;
          if (!map.is_free(grid.cell_center(Eigen::Vector3i(i, j, k)), radius)) ++unsafe;
          if (!grid.occupied(v)) passable[v] = 1;
        }
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
  const int dim[3] = {dims.x(), dims.y(), dims.z()};
  for (std::size_t head = 0; head < queue.size() && !q.connected; ++head) {
    const std::size_t cur = queue[head];
    const int cx = static_cast<int>(cur % nx), cy = static_cast<int>((cur / nx) % static_cast<std::size_t>(dim[1])),
              cz = static_cast<int>(cur / nxy);
    for (const world::GridMove& m : moves) {
      const int x = cx + m.dx, y = cy + m.dy, z = cz + m.dz;
      if (x < 0 || y < 0 || z < 0 || x >= dim[0] || y >= dim[1] || z >= dim[2]) continue;
      const std::size_t v = static_cast<std::size_t>(static_cast<std::ptrdiff_t>(cur) + m.offset);
      if (passable[v] != 1) continue;
      if (!world::block_free(grid, cur, m)) continue;
      passable[v] = 2;
      if (v == to) q.connected = true;
      queue.push_back(v);
    }
  }
  return q;
}

}  // namespace miner::heuristic
