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
}  // namespace

std::array<GridMove, 26> grid_moves(const Eigen::Vector3i& dims) {
  const std::ptrdiff_t sy = dims.x(), sz = static_cast<std::ptrdiff_t>(dims.x()) * dims.y();
  std::array<GridMove, 26> moves{};
  int n = 0;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int nonzero = (dx != 0) + (dy != 0) + (dz != 0);
        if (nonzero == 0) continue;
        GridMove& m = moves[static_cast<std::size_t>(n++)];
        m.dx = dx;
        m.dy = dy;
        m.dz = dz;
        m.length = nonzero == 1 ? 1.0 : nonzero == 2 ? kSqrt2 : kSqrt3;
        m.offset = dx + dy * sy + dz * sz;
        m.n_between = 0;
        // Every cell of the block from the current cell to the neighbour except the two ends.
        for (int z = 0; z <= std::abs(dz); ++z)
          for (int y = 0; y <= std::abs(dy); ++y)
            for (int x = 0; x <= std::abs(dx); ++x) {
              const std::ptrdiff_t o = x * dx + y * dy * sy + z * dz * sz;
              if (o != 0 && o != m.offset) m.between[static_cast<std::size_t>(m.n_between++)] = o;
            }
      }
  return moves;
}

namespace {

/// The octile distance in cells for coordinate differences (the same expression as
/// octile_distance at resolution 1, so costs and the expansion order are unchanged).
double octile_cells(int ax, int ay, int az) {
  std::array<int, 3> d{std::abs(ax), std::abs(ay), std::abs(az)};
  std::sort(d.begin(), d.end(), std::greater<>());
  return 1.0 * (kSqrt3 * d[2] + kSqrt2 * (d[1] - d[2]) + (d[0] - d[1]));
}

Eigen::Vector3i endpoint_cell(const Map& map, const VoxelGrid& grid, const Eigen::Vector3d& p,
                              const std::string& what) {
  map.require_free(p, grid.robot_radius(), what);
  const auto cell = grid.cell_of(p);
  if (!cell) throw Error(what + " " + format_point(p) + " lies outside the grid");
  if (grid.occupied(*cell)) {
    std::ostringstream os;
    // The last layer of cells, when the resolution does not divide the extent, has its centre
    // past the bounds and is blocked (VoxelGrid): that is the cause, not an obstacle (issue 20,
    // fourth campaign: such a goal was blamed on "an obstacle inflated by the robot radius").
    const Eigen::Vector3d centre = map.bounds().min + (cell->cast<double>().array() + 0.5).matrix() * grid.resolution();
    for (int k = 0; k < 3; ++k)
      if (centre[k] > map.bounds().max[k]) {
        os << what << " " << format_point(p) << " lies in the last grid cell along " << "xyz"[k] << ", whose centre "
           << centre[k] << " m is past the map's bounds (max " << map.bounds().max[k] << " m): the resolution "
           << grid.resolution() << " m does not divide the extent " << map.bounds().extent()[k]
           << " m and such cells are blocked; move it inside or use a resolution that divides the extent";
        throw Error(os.str());
      }
    os << what << " " << format_point(p) << " lies in an occupied grid cell (clearance "
       << map.clearance(p) << " m; at resolution " << grid.resolution()
       << " m the cell overlaps an obstacle (a box or a blocked voxel) inflated by the robot radius " << grid.robot_radius()
       << " m); move it away from obstacles or use a finer resolution";
    throw Error(os.str());
  }
  return *cell;
}

}  // namespace

double octile_distance(const Eigen::Vector3i& a, const Eigen::Vector3i& b, double resolution) {
  // Differences in 64 bits: cells 2^31 apart do not wrap (tenth campaign L22).
  std::array<double, 3> d{};
  for (int k = 0; k < 3; ++k) d[static_cast<std::size_t>(k)] = std::fabs(static_cast<double>(static_cast<std::int64_t>(a[k]) - b[k]));
  std::sort(d.begin(), d.end(), std::greater<>());
  return resolution * (kSqrt3 * d[2] + kSqrt2 * (d[1] - d[2]) + (d[0] - d[1]));
}

GridPath astar(const Map& map, const VoxelGrid& grid, const Eigen::Vector3d& start,
               const Eigen::Vector3d& goal, const std::string& start_name, const std::string& goal_name) {
  // The grid is this map's (issue 20, tenth campaign L7: a grid of an empty map walked A*
  // through the walls of another with the same bounds).
  if (grid.map_fingerprint() != map.fingerprint())
    throw Error("astar: the grid was built from another map (its bounds, resolution, obstacles or voxels differ); "
                "build the VoxelGrid from this map");
  const Eigen::Vector3i s = endpoint_cell(map, grid, start, start_name);
  const Eigen::Vector3i g = endpoint_cell(map, grid, goal, goal_name);
  // Index arithmetic in the inner loop: A* runs inside every generated map's solvability
  // check and every dataset sample, so this loop is most of their cost.
  const std::array<GridMove, 26> moves = grid_moves(grid.dims());
  const std::size_t nx = static_cast<std::size_t>(grid.dims().x()), ny = static_cast<std::size_t>(grid.dims().y());
  const int dims[3] = {grid.dims().x(), grid.dims().y(), grid.dims().z()};

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

  // A flood from the goal, one cell per A* expansion: when it runs out first, the goal sits in
  // a pocket without the start and the answer "unreachable" costs the pocket's size, not the
  // whole grid's (issue 20, eighth campaign H1: an enclosed goal on a 64 M-cell grid ran past
  // a minute). Steps are symmetric (the same cells lie between a and b as between b and a),
  // so the flood's cells are exactly those that reach the goal. It stops once it meets a cell A*
  // has reached (then the start reaches the goal).
  // One flood step per kFloodStride expansions: an enclosed goal costs at most kFloodStride x its
  // pocket, a reachable one at most 1 / kFloodStride more work (at 1 the flood cost dataset
  // generation 16 %; `miner bench`-style timing with farm-bench, session 28).
  constexpr std::size_t kFloodStride = 8;
  std::vector<std::uint8_t> reaches_goal(n, 0);
  std::size_t turns = 0;  // of the loop below
  std::vector<std::uint32_t> flood{static_cast<std::uint32_t>(gi)};  // n <= kMaxGridCells < 2^32
  std::size_t flood_next = 0;
  reaches_goal[gi] = 1;
  bool flood_done = si == gi;
  const auto flood_step = [&]() {
    if (flood_next == flood.size()) return;
    const std::size_t cur = flood[flood_next++];
    const int cx = static_cast<int>(cur % nx), cy = static_cast<int>((cur / nx) % ny), cz = static_cast<int>(cur / (nx * ny));
    for (const GridMove& m : moves) {
      const int x = cx + m.dx, y = cy + m.dy, z = cz + m.dz;
      if (x < 0 || y < 0 || z < 0 || x >= dims[0] || y >= dims[1] || z >= dims[2]) continue;
      const std::size_t ni = static_cast<std::size_t>(static_cast<std::ptrdiff_t>(cur) + m.offset);
      if (reaches_goal[ni] || grid.occupied(ni) || !block_free(grid, cur, m)) continue;
      reaches_goal[ni] = 1;
      flood.push_back(static_cast<std::uint32_t>(ni));
      // A cell A* has reached from the start: start and goal are connected, the flood's job is done.
      if (ni == si || cost_to_come[ni] < kInf) flood_done = true;
    }
  };

  GridPath result;
  while (!open.empty()) {
    if (!flood_done && turns++ % kFloodStride == 0) {
      flood_step();
      if (!flood_done && flood_next == flood.size() && !reaches_goal[si]) {
        std::ostringstream os;
        os << "goal " << format_point(goal) << " is unreachable from start " << format_point(start)
           << " for robot radius " << grid.robot_radius() << " m: the " << flood.size()
           << " free cells that reach the goal do not include the start (the goal is enclosed)";
        throw NoSolution(os.str());
      }
      if (flood_next == flood.size()) flood_done = true;
      if (flood_done) std::vector<std::uint32_t>().swap(flood);  // the start reaches the goal: done
    }
    const std::size_t cur = open.top().second;
    open.pop();
    if (closed[cur]) continue;
    closed[cur] = 1;
    ++result.expanded;
    if (cur == gi) break;
    const int cx = static_cast<int>(cur % nx), cy = static_cast<int>((cur / nx) % ny), cz = static_cast<int>(cur / (nx * ny));
    const auto at = [cur](std::ptrdiff_t offset) { return static_cast<std::size_t>(static_cast<std::ptrdiff_t>(cur) + offset); };
    for (const GridMove& m : moves) {
      const int x = cx + m.dx, y = cy + m.dy, z = cz + m.dz;
      if (x < 0 || y < 0 || z < 0 || x >= dims[0] || y >= dims[1] || z >= dims[2]) continue;
      const std::size_t ni = at(m.offset);
      if (closed[ni] || grid.occupied(ni)) continue;
      if (!block_free(grid, cur, m)) continue;  // the cells the step passes between
      const double tentative = cost_to_come[cur] + m.length;
      if (tentative < cost_to_come[ni]) {
        cost_to_come[ni] = tentative;
        parent[ni] = static_cast<std::int64_t>(cur);
        open.emplace(tentative + octile_cells(x - g.x(), y - g.y(), z - g.z()), ni);
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
