#include "miner/world/astar.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <queue>
#include <sstream>

#include "miner/core/error.hpp"
#include "miner/world/map.hpp"
#include "miner/world/voxel_grid.hpp"

namespace miner::world {

namespace {

constexpr double kSqrt2 = 1.4142135623730951;
constexpr double kSqrt3 = 1.7320508075688772;

struct Move {
  Eigen::Vector3i delta;
  double length;  // in cells
};

std::array<Move, 26> make_moves() {
  std::array<Move, 26> moves{};
  int n = 0;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int nonzero = (dx != 0) + (dy != 0) + (dz != 0);
        if (nonzero == 0) continue;
        moves[n++] = {{dx, dy, dz}, nonzero == 1 ? 1.0 : nonzero == 2 ? kSqrt2 : kSqrt3};
      }
  return moves;
}

/// Every cell of the block spanned by `from` and `from + delta` is free.
bool block_free(const VoxelGrid& grid, const Eigen::Vector3i& from, const Eigen::Vector3i& delta) {
  for (int z = 0; z <= std::abs(delta.z()); ++z)
    for (int y = 0; y <= std::abs(delta.y()); ++y)
      for (int x = 0; x <= std::abs(delta.x()); ++x) {
        const Eigen::Vector3i c(from.x() + x * delta.x(), from.y() + y * delta.y(),
                                from.z() + z * delta.z());
        if (grid.occupied(c)) return false;
      }
  return true;
}

Eigen::Vector3i endpoint_cell(const Map& map, const VoxelGrid& grid, const Eigen::Vector3d& p,
                              const std::string& what) {
  map.require_free(p, grid.robot_radius(), what);
  const auto cell = grid.cell_of(p);
  if (!cell) throw Error(what + " " + format_point(p) + " lies outside the grid");
  if (grid.occupied(*cell)) {
    std::ostringstream os;
    os << what << " " << format_point(p) << " lies in an occupied grid cell (clearance "
       << map.clearance(p) << " m; at resolution " << grid.resolution()
       << " m the cell overlaps an obstacle inflated by the robot radius " << grid.robot_radius()
       << " m); move it away from obstacles or use a finer resolution";
    throw Error(os.str());
  }
  return *cell;
}

}  // namespace

double octile_distance(const Eigen::Vector3i& a, const Eigen::Vector3i& b, double resolution) {
  std::array<int, 3> d{std::abs(a.x() - b.x()), std::abs(a.y() - b.y()), std::abs(a.z() - b.z())};
  std::sort(d.begin(), d.end(), std::greater<>());
  return resolution * (kSqrt3 * d[2] + kSqrt2 * (d[1] - d[2]) + (d[0] - d[1]));
}

GridPath astar(const Map& map, const VoxelGrid& grid, const Eigen::Vector3d& start,
               const Eigen::Vector3d& goal) {
  const Eigen::Vector3i s = endpoint_cell(map, grid, start, "start");
  const Eigen::Vector3i g = endpoint_cell(map, grid, goal, "goal");
  static const std::array<Move, 26> kMoves = make_moves();

  const std::size_t n = grid.cell_count();
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<double> cost_to_come(n, kInf);
  std::vector<std::int64_t> parent(n, -1);
  std::vector<std::uint8_t> closed(n, 0);

  // Open list ordered by f = g + h, ties broken by the cell index: deterministic.
  using Entry = std::pair<double, std::size_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> open;
  const std::size_t si = grid.index(s), gi = grid.index(g);
  cost_to_come[si] = 0.0;
  open.emplace(octile_distance(s, g, 1.0), si);

  GridPath result;
  while (!open.empty()) {
    const std::size_t cur = open.top().second;
    open.pop();
    if (closed[cur]) continue;
    closed[cur] = 1;
    ++result.expanded;
    if (cur == gi) break;
    const Eigen::Vector3i c = grid.coords(cur);
    for (const Move& m : kMoves) {
      const Eigen::Vector3i nb = c + m.delta;
      if (!grid.contains(nb)) continue;
      const std::size_t ni = grid.index(nb);
      if (closed[ni] || grid.occupied(ni)) continue;
      if (!block_free(grid, c, m.delta)) continue;
      const double tentative = cost_to_come[cur] + m.length;
      if (tentative < cost_to_come[ni]) {
        cost_to_come[ni] = tentative;
        parent[ni] = static_cast<std::int64_t>(cur);
        open.emplace(tentative + octile_distance(nb, g, 1.0), ni);
      }
    }
  }
  if (!closed[gi]) {
    std::ostringstream os;
    os << "goal " << format_point(goal) << " is unreachable from start " << format_point(start)
       << " for robot radius " << grid.robot_radius() << " m: A* exhausted the "
       << result.expanded << " free cells reachable from the start";
    throw NoSolution(os.str());
  }

  for (std::int64_t i = static_cast<std::int64_t>(gi); i >= 0; i = parent[i]) {
    result.cells.push_back(grid.coords(static_cast<std::size_t>(i)));
  }
  std::reverse(result.cells.begin(), result.cells.end());
  result.grid_cost = cost_to_come[gi] * grid.resolution();

  result.points.push_back(start);
  // Start and goal in one cell: the straight segment between them (free: both are clear
  // of the inflated obstacles and a cell's free block is convex), not a detour through the
  // cell's centre; start == goal costs 0.
  if (si != gi) {
    for (const auto& c : result.cells) result.points.push_back(grid.cell_center(c));
  }
  result.points.push_back(goal);
  for (std::size_t i = 1; i < result.points.size(); ++i) {
    result.cost += (result.points[i] - result.points[i - 1]).norm();
  }
  return result;
}

}  // namespace miner::world
