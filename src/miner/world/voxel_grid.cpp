#include "miner/world/voxel_grid.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "miner/core/error.hpp"
#include "miner/world/map.hpp"
#include "miner/world/voxel_layer.hpp"

namespace miner::world {

namespace {

/// Lower edge of cell i along one axis, computed the one way every query computes it.
double cell_edge(double origin, double res, int i) { return origin + i * res; }

/// The first and last cell index whose open interval (edge(i), edge(i+1)) meets the
/// closed interval [lo, hi], clamped to [0, n-1]; first > last when none does. The
/// estimate from division is corrected against the cell edges themselves, so the
/// answer is exact for the grid's own floating-point edges.
std::pair<int, int> cell_span(double origin, double res, int n, double lo, double hi) {
  int first = static_cast<int>(std::max(0.0, std::min<double>(n - 1, std::floor((lo - origin) / res))));
  while (first > 0 && cell_edge(origin, res, first) > lo) --first;
  while (first < n && cell_edge(origin, res, first + 1) <= lo) ++first;
  int last = static_cast<int>(std::max(0.0, std::min<double>(n - 1, std::ceil((hi - origin) / res) - 1.0)));
  while (last < n - 1 && cell_edge(origin, res, last + 1) < hi) ++last;
  while (last >= 0 && cell_edge(origin, res, last) >= hi) --last;
  return {first, last};
}
}  // namespace

VoxelGrid::VoxelGrid(const Map& map, double robot_radius)
    : origin_(map.bounds().min), resolution_(map.resolution()), robot_radius_(robot_radius),
      map_fingerprint_(map.fingerprint()) {
  // A robot radius, as every query has (tenth campaign L10: 1e300 made every cell occupied).
  check_robot_radius(robot_radius, "robot radius");
  dims_ = grid_dims(map.bounds(), resolution_);  // checked when the map was built (REQ-WORLD-002)
  occupancy_.assign(static_cast<std::size_t>(dims_.x()) * static_cast<std::size_t>(dims_.y()) *
                        static_cast<std::size_t>(dims_.z()),
                    0);

  // Cells whose centre lies outside the bounds (the last layer when extent/res is not whole).
  for (int k = 0; k < 3; ++k) {
    for (int i = dims_[k] - 1; i >= 0; --i) {
      if (origin_[k] + (i + 0.5) * resolution_ <= map.bounds().max[k]) break;
      Eigen::Vector3i from(0, 0, 0), to = dims_ - Eigen::Vector3i::Ones();
      from[k] = to[k] = i;
      for (int z = from.z(); z <= to.z(); ++z)
        for (int y = from.y(); y <= to.y(); ++y)
          for (int x = from.x(); x <= to.x(); ++x) occupancy_[index(x, y, z)] = 1;
    }
  }
  // Each grown box covers a block of cells: cell i's interior (o + i res, o + (i+1) res) meets
  // [lo, hi] iff o + (i+1) res > lo and o + i res < hi.
  std::vector<std::pair<Eigen::Vector3i, Eigen::Vector3i>> blocks;
  blocks.reserve(map.obstacles().size());
  for (const Box& obstacle : map.obstacles()) {
    const Box b = obstacle.inflated(robot_radius);
    Eigen::Vector3i lo, hi;
    bool empty = false;
    for (int k = 0; k < 3; ++k) {
      const auto [first, last] = cell_span(origin_[k], resolution_, dims_[k], b.min[k], b.max[k]);
      if (last < first) { empty = true; break; }
      lo[k] = first;
      hi[k] = last;
    }
    if (!empty) blocks.emplace_back(lo, hi);
  }
  mark_blocks(blocks);
  if (map.voxels()) mark_voxels(*map.voxels(), map.bounds());
}

void VoxelGrid::mark_blocks(const std::vector<std::pair<Eigen::Vector3i, Eigen::Vector3i>>& blocks) {
  // Plane by plane, a 2D difference array of the blocks that span the plane, summed: the work
  // is O(sum of the blocks' heights + cells) however much the blocks overlap (issue 20: filling
  // each block cell by cell took hours for 10^4 boxes each covering a percent of the map).
  const int nx = dims_.x(), ny = dims_.y(), nz = dims_.z();
  std::vector<std::vector<std::size_t>> starting(static_cast<std::size_t>(nz));
  for (std::size_t i = 0; i < blocks.size(); ++i) starting[static_cast<std::size_t>(blocks[i].first.z())].push_back(i);
  const std::size_t stride = static_cast<std::size_t>(nx) + 1;
  std::vector<int> diff(stride * (static_cast<std::size_t>(ny) + 1));
  std::vector<std::size_t> active;
  for (int z = 0; z < nz; ++z) {
    for (std::size_t i : starting[static_cast<std::size_t>(z)]) active.push_back(i);
    active.erase(std::remove_if(active.begin(), active.end(), [&](std::size_t i) { return blocks[i].second.z() < z; }),
                 active.end());
    if (active.empty()) continue;
    std::fill(diff.begin(), diff.end(), 0);
    for (std::size_t i : active) {
      const auto& [lo, hi] = blocks[i];
      const std::size_t x0 = static_cast<std::size_t>(lo.x()), x1 = static_cast<std::size_t>(hi.x()) + 1;
      const std::size_t y0 = static_cast<std::size_t>(lo.y()), y1 = static_cast<std::size_t>(hi.y()) + 1;
      ++diff[y0 * stride + x0];
      --diff[y0 * stride + x1];
      --diff[y1 * stride + x0];
      ++diff[y1 * stride + x1];
    }
    // Prefix sums along x, then along y: diff then holds how many blocks cover each cell.
    for (int y = 0; y < ny; ++y)
      for (int x = 1; x < nx; ++x) diff[y * stride + x] += diff[y * stride + x - 1];
    for (int y = 1; y < ny; ++y)
      for (int x = 0; x < nx; ++x) diff[y * stride + x] += diff[(y - 1) * stride + x];
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x)
        if (diff[y * stride + x] > 0) occupancy_[index(x, y, z)] = 1;
  }
}

void VoxelGrid::mark_voxels(const VoxelObstacles& voxels, const Box& bounds) {
  // The grid and the layer share cells (Map checks the lattice), offset by whole cells. Cell c
  // is occupied iff its open interior comes within r of a blocked voxel's cube: the exact
  // rounded inflation (tighter than the boxes' box-shaped growth), from the cube-to-cube
  // distance transform; every interior point of a free cell is farther than r from them.
  const VoxelLayer& layer = voxels.layer();
  Eigen::Vector3i offset;
  for (int k = 0; k < 3; ++k)
    offset[k] = layer.origin_cells()[k] - static_cast<int>(std::round(bounds.min[k] / resolution_));
  // The mask has a margin of m cells each side: voxels just outside the grid still reach into it.
  const int m = static_cast<int>(std::ceil(robot_radius_ / resolution_)) + 1;
  const Eigen::Vector3i pdims = dims_.array() + 2 * m;
  const auto pindex = [&](const Eigen::Vector3i& c) {
    return (static_cast<std::size_t>(c.z()) * pdims.y() + c.y()) * pdims.x() + c.x();
  };
  std::vector<std::uint8_t> mask(static_cast<std::size_t>(pdims.x()) * pdims.y() * pdims.z(), 0);
  for (int z = 0; z < layer.dims().z(); ++z)
    for (int y = 0; y < layer.dims().y(); ++y)
      for (int x = 0; x < layer.dims().x(); ++x) {
        if (!voxels.blocked(layer.index(x, y, z))) continue;
        const Eigen::Vector3i c = Eigen::Vector3i(x, y, z) + offset + Eigen::Vector3i::Constant(m);
        if ((c.array() >= 0).all() && (c.array() < pdims.array()).all()) mask[pindex(c)] = 1;
      }
  const std::vector<double> sq = squared_distance_transform(mask, pdims, true);
  // The open cell meets the grown cube iff the cubes are closer than r (a face-neighbour at
  // distance 0 only touches for r = 0). Rounding slack on (r / res)^2 errs towards occupied.
  constexpr double kRadiusRounding = 1e-12;
  const double limit = (robot_radius_ / resolution_) * (robot_radius_ / resolution_) * (1.0 + kRadiusRounding);
  for (std::size_t i = 0; i < mask.size(); ++i) mask[i] = mask[i] || sq[i] < limit;
  for (int z = 0; z < dims_.z(); ++z)
    for (int y = 0; y < dims_.y(); ++y)
      for (int x = 0; x < dims_.x(); ++x) occupancy_[index(x, y, z)] |= mask[pindex(Eigen::Vector3i(x + m, y + m, z + m))];
}

std::size_t VoxelGrid::occupied_count() const {
  return static_cast<std::size_t>(std::count(occupancy_.begin(), occupancy_.end(), 1));
}

Eigen::Vector3i VoxelGrid::coords(std::size_t idx) const {
  const auto nx = static_cast<std::size_t>(dims_.x());
  const auto ny = static_cast<std::size_t>(dims_.y());
  return {static_cast<int>(idx % nx), static_cast<int>((idx / nx) % ny),
          static_cast<int>(idx / (nx * ny))};
}

Eigen::Vector3d VoxelGrid::cell_center(std::size_t idx) const { return cell_center(coords(idx)); }

std::optional<Eigen::Vector3i> VoxelGrid::cell_of(const Eigen::Vector3d& p) const {
  Eigen::Vector3i c;
  for (int k = 0; k < 3; ++k) {
    const double u = (p[k] - origin_[k]) / resolution_;
    if (!(u >= 0.0) || u > static_cast<double>(dims_[k])) return std::nullopt;
    c[k] = std::min(static_cast<int>(std::floor(u)), dims_[k] - 1);
  }
  return c;
}

}  // namespace miner::world
