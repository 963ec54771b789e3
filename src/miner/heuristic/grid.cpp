#include "miner/heuristic/grid.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <type_traits>

#include "miner/core/error.hpp"
#include "miner/core/text.hpp"
#include "miner/plan/heuristic_region.hpp"
#include "miner/world/map.hpp"

namespace miner::heuristic {

Eigen::Vector3i cell_coords(const Eigen::Vector3i& dims, std::size_t index) {
  // Fourteenth campaign L2: an index past the grid answered coordinates outside it. The check
  // reuses the layer z = index / (nx ny) the answer needs anyway: the filter's searches call
  // this once per visited cell.
  if ((dims.array() < 1).any())
    throw Error("grid cell index " + std::to_string(index) + ": the grid " + std::to_string(dims.x()) + " x " +
                std::to_string(dims.y()) + " x " + std::to_string(dims.z()) + " has no cells");
  const auto nx = static_cast<std::size_t>(dims.x());
  const std::size_t nxy = nx * static_cast<std::size_t>(dims.y());
  const std::size_t z = index / nxy;
  if (z >= static_cast<std::size_t>(dims.z()))
    throw Error("grid cell index " + std::to_string(index) + " lies outside the " + std::to_string(dims.x()) + " x " +
                std::to_string(dims.y()) + " x " + std::to_string(dims.z()) + " grid");
  const std::size_t in_layer = index - z * nxy;
  return {static_cast<int>(in_layer % nx), static_cast<int>(in_layer / nx), static_cast<int>(z)};
}

Eigen::Vector3d cell_size(const world::Box& b, const Eigen::Vector3i& dims) {
  // Fifteenth campaign F9: zero-extent bounds gave NaN cells (cell_of cast NaN to int) and
  // dims 0 a cell (-1, ..) "clamped onto the grid". Every helper that places cells reads the
  // cell size here, so the grid is checked once here.
  const Eigen::Vector3d c = (b.max - b.min).cwiseQuotient(dims.cast<double>());
  if ((dims.array() < 1).any() || !(c.array() > 0.0).all() || !c.allFinite())
    throw Error("grid of " + std::to_string(dims.x()) + " x " + std::to_string(dims.y()) + " x " +
                std::to_string(dims.z()) + " cells over the bounds (" + short_number(b.min.x()) + ", " +
                short_number(b.min.y()) + ", " + short_number(b.min.z()) + ") - (" + short_number(b.max.x()) + ", " +
                short_number(b.max.y()) + ", " + short_number(b.max.z()) +
                "): needs at least one cell per axis and bounds with max > min, finite, on every axis");
  return c;
}

Eigen::Vector3i cell_of(const world::Box& b, const Eigen::Vector3i& dims, const Eigen::Vector3d& p) {
  // Fourteenth campaign L2: NaN was cast to int (undefined; -2147483648 in practice).
  if (!p.allFinite())
    throw Error("grid point (" + short_number(p.x()) + ", " + short_number(p.y()) + ", " + short_number(p.z()) +
                ") is not finite: it lies in no cell");
  const Eigen::Vector3d c = cell_size(b, dims);
  Eigen::Vector3i idx;
  for (int a = 0; a < 3; ++a) {
    const double f = std::floor((p[a] - b.min[a]) / c[a]);
    idx[a] = static_cast<int>(std::clamp(f, 0.0, static_cast<double>(dims[a] - 1)));
  }
  return idx;
}

world::Box cell_box(const world::Box& b, const Eigen::Vector3i& dims, const Eigen::Vector3i& c) {
  const Eigen::Vector3d s = cell_size(b, dims);
  const Eigen::Vector3d lo = b.min + c.cast<double>().cwiseProduct(s);
  return {lo, lo + s};
}

bool box_covered(const world::Box& cell, const std::vector<world::Box>& boxes, std::uint64_t* budget) {
  // Breakpoints of every box face strictly inside the cell, per axis: between two
  // consecutive ones no face is crossed, so each sub-box's centre decides for all of it.
  std::vector<double> cuts[3];
  for (int a = 0; a < 3; ++a) {
    cuts[a] = {cell.min[a], cell.max[a]};
    for (const world::Box& o : boxes)
      for (double v : {o.min[a], o.max[a]})
        if (v > cell.min[a] && v < cell.max[a]) cuts[a].push_back(v);
    std::sort(cuts[a].begin(), cuts[a].end());
    cuts[a].erase(std::unique(cuts[a].begin(), cuts[a].end()), cuts[a].end());
  }
  // Bounded work: the sub-boxes times the boxes each is tested against (double: no wrap).
  const double tests = static_cast<double>(cuts[0].size() - 1) * static_cast<double>(cuts[1].size() - 1) *
                       static_cast<double>(cuts[2].size() - 1) * static_cast<double>(boxes.size());
  if (tests > static_cast<double>(kMaxCoverTests)) return false;
  if (budget != nullptr) {
    if (tests > static_cast<double>(*budget)) return false;
    *budget -= static_cast<std::uint64_t>(tests);
  }
  for (std::size_t i = 0; i + 1 < cuts[0].size(); ++i)
    for (std::size_t j = 0; j + 1 < cuts[1].size(); ++j)
      for (std::size_t k = 0; k + 1 < cuts[2].size(); ++k) {
        const Eigen::Vector3d mid(0.5 * (cuts[0][i] + cuts[0][i + 1]), 0.5 * (cuts[1][j] + cuts[1][j + 1]),
                                  0.5 * (cuts[2][k] + cuts[2][k + 1]));
        const bool inside = std::any_of(boxes.begin(), boxes.end(), [&](const world::Box& o) {
          return (mid.array() >= o.min.array()).all() && (mid.array() <= o.max.array()).all();
        });
        if (!inside) return false;
      }
  return true;
}

namespace {

/// Channel E of a map's voxel layer, from occupancy in one pass over the voxels (never per
/// voxel per cell): a voxel is grown-blocked when a blocked voxel's centre lies within the
/// radius of its centre (the layer's distance transform); a heuristic cell is kPartial when it
/// holds a grown-blocked voxel centre, kSolid when every voxel centre it holds is grown-blocked
/// and the layer covers the whole cell.
void encode_voxels(const world::Map& map, const Eigen::Vector3i& dims, double radius, std::vector<std::uint8_t>& e) {
  const world::VoxelObstacles& voxels = *map.voxels();
  const world::VoxelLayer& layer = voxels.layer();
  const world::Box& b = map.bounds();
  const Eigen::Vector3d c = cell_size(b, dims);
  // Heuristic cell of each voxel coordinate, per axis (-1: the voxel's centre is off the grid).
  std::array<std::vector<int>, 3> to_cell;
  for (int a = 0; a < 3; ++a) {
    to_cell[a].resize(static_cast<std::size_t>(layer.dims()[a]));
    for (int v = 0; v < layer.dims()[a]; ++v) {
      const double centre = (layer.origin_cells()[a] + v + 0.5) * layer.resolution();
      const double f = std::floor((centre - b.min[a]) / c[a]);
      to_cell[a][v] = f >= 0.0 && f < dims[a] ? static_cast<int>(f) : -1;
    }
  }
  const auto cells = static_cast<std::size_t>(dims.prod());
  std::vector<std::uint32_t> total(cells, 0), grown(cells, 0);
  const float limit = static_cast<float>(radius / layer.resolution());
  std::size_t idx = 0;
  for (int z = 0; z < layer.dims().z(); ++z)
    for (int y = 0; y < layer.dims().y(); ++y) {
      const int kz = to_cell[2][z], ky = to_cell[1][y];
      if (kz < 0 || ky < 0) {
        idx += static_cast<std::size_t>(layer.dims().x());
        continue;
      }
      const std::size_t row = cell_index(dims, 0, ky, kz);
      for (int x = 0; x < layer.dims().x(); ++x, ++idx) {
        const int kx = to_cell[0][x];
        if (kx < 0) continue;
        ++total[row + kx];
        grown[row + kx] += voxels.centre_distance(idx) <= limit;
      }
    }
  const world::Box covered = layer.bounds();
  for (std::size_t i = 0; i < cells; ++i) {
    if (grown[i] == 0) continue;
    const world::Box cell = cell_box(b, dims, cell_coords(dims, i));
    const bool inside = (cell.min.array() >= covered.min.array()).all() && (cell.max.array() <= covered.max.array()).all();
    const std::uint8_t level = grown[i] == total[i] && inside ? kSolid : kPartial;
    e[i] = std::max(e[i], level);
  }
}

}  // namespace

namespace {
/// The kPassabilitySubcells^3 sub-cell centres of a cell, per axis, and which of them a closed
/// box holds (bit x + 4 y + 16 z), by plain comparisons. The one definition of a centre being
/// inside a box: P's blocked sub-cells and E's pre-filter of the exact cover test (a centre
/// outside every box is a point of the cell outside their union) both read it.
struct SubcellCentres {
  std::array<std::array<double, kPassabilitySubcells>, 3> at{};
  explicit SubcellCentres(const world::Box& cell) {
    for (std::size_t a = 0; a < 3; ++a)
      for (std::size_t s = 0; s < kPassabilitySubcells; ++s)
        at[a][s] = cell.min[static_cast<int>(a)] +
                   (static_cast<double>(s) + 0.5) * cell.extent()[static_cast<int>(a)] / kPassabilitySubcells;
  }
  std::uint64_t inside(const world::Box& g) const {
    std::array<unsigned, 3> in{};  // per axis, bit s: centre s within [g.min, g.max]
    for (std::size_t a = 0; a < 3; ++a)
      for (std::size_t s = 0; s < kPassabilitySubcells; ++s)
        if (at[a][s] >= g.min[static_cast<int>(a)] && at[a][s] <= g.max[static_cast<int>(a)]) in[a] |= 1U << s;
    std::uint64_t mask = 0;
    for (unsigned z = 0; z < kPassabilitySubcells; ++z)
      for (unsigned y = 0; y < kPassabilitySubcells; ++y)
        if ((in[2] >> z & 1U) && (in[1] >> y & 1U))
          mask |= static_cast<std::uint64_t>(in[0]) << (kPassabilitySubcells * (y + kPassabilitySubcells * z));
    return mask;
  }
};
}  // namespace

std::uint64_t subcells_inside(const world::Box& cell, const world::Box& g) { return SubcellCentres(cell).inside(g); }

namespace {

/// The sub-cells of `cell` whose centres lie in a grown-blocked voxel (the voxel holding the
/// centre; centres off the layer are not blocked by it).
std::uint64_t subcells_in_grown_voxels(const world::VoxelObstacles& voxels, double radius, const world::Box& cell) {
  constexpr int n = kPassabilitySubcells;
  const world::VoxelLayer& layer = voxels.layer();
  const float limit = static_cast<float>(radius / layer.resolution());
  const Eigen::Vector3d h = cell.extent() / n;
  int coord[3][n];
  for (int a = 0; a < 3; ++a)
    for (int s = 0; s < n; ++s) {
      const double centre = cell.min[a] + (s + 0.5) * h[a];
      const int v = static_cast<int>(std::floor(centre / layer.resolution())) - layer.origin_cells()[a];
      coord[a][s] = v >= 0 && v < layer.dims()[a] ? v : -1;
    }
  std::uint64_t blocked = 0;
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        if (coord[0][x] < 0 || coord[1][y] < 0 || coord[2][z] < 0) continue;
        if (voxels.centre_distance(layer.index(coord[0][x], coord[1][y], coord[2][z])) <= limit)
          blocked |= std::uint64_t{1} << (x + n * (y + n * z));
      }
  return blocked;
}

/// The cells a grown box meets (lo..hi) and those it holds whole (inner_lo..inner_hi), per axis.
struct BoxCells {
  Eigen::Vector3i lo, hi, inner_lo, inner_hi;
  bool has_inner() const { return (inner_lo.array() <= inner_hi.array()).all(); }
};


/// encode()'s working arrays, kept by each thread between calls (issue 16: made afresh, the
/// ~300 kB of them were mapped and page-faulted on every query, which cost more than the
/// encoding itself on the sim maps). Their contents never carry from one call to the next.
struct EncodeScratch {
  std::vector<world::Box> grown, local;
  std::vector<BoxCells> range;
  std::vector<std::uint32_t> offset, touching;
  std::vector<std::int32_t> cover;
  std::vector<std::pair<std::uint32_t, std::uint64_t>> box_blocked;

  /// Gives back arrays grown past kKeptBytes (a huge map's), so that one such query does not
  /// hold its memory for the thread's life.
  void trim() {
    constexpr std::size_t kKeptBytes = std::size_t{64} << 20;
    auto trim_one = [](auto& v) {
      if (v.capacity() * sizeof(v[0]) > kKeptBytes) std::remove_reference_t<decltype(v)>().swap(v);
    };
    trim_one(grown);
    trim_one(local);
    trim_one(range);
    trim_one(offset);
    trim_one(touching);
    trim_one(cover);
    trim_one(box_blocked);
  }
};

/// E, and P when `passability` is given (see grid.hpp).
std::vector<std::uint8_t> encode(const world::Map& map, const Eigen::Vector3i& dims, double radius,
                                 std::vector<std::uint8_t>* passability) {
  thread_local EncodeScratch scratch;
  struct Trim {
    EncodeScratch& s;
    ~Trim() { s.trim(); }
  } trim_on_exit{scratch};
  // Tenth campaign recheck: dims of 0 encoded an empty grid, a NaN radius grew no obstacle
  // (every cell free). The region's cell rule (each dim >= 1, at most kMaxCells, no int wrap)
  // and the map's radius rule.
  const std::size_t cells = plan::HeuristicRegion::cell_count(dims);
  world::check_robot_radius(radius, "encode: robot radius");
  const world::Box& b = map.bounds();
  const Eigen::Vector3d c = cell_size(b, dims);
  std::vector<std::uint8_t> e(cells, kFree);
  // The grown obstacles and the cell range each one meets: cell i's closed box
  // [b + i c, b + (i+1) c] meets [g.min, g.max] iff (g.min - b)/c - 1 <= i <= (g.max - b)/c;
  // and the range of cells inside it (inner, empty when lo > hi), from the cells' own edges
  // (cell_box's numbers, so the test is exactly cell_box(i) within g).
  std::vector<world::Box>& grown = scratch.grown;
  std::vector<BoxCells>& range = scratch.range;
  grown.clear();
  range.clear();
  std::array<std::vector<double>, 3> edge_lo, edge_hi;
  for (int a = 0; a < 3; ++a)
    for (int i = 0; i < dims[a]; ++i) {
      const world::Box cb = cell_box(b, dims, Eigen::Vector3i::Constant(i));
      edge_lo[static_cast<std::size_t>(a)].push_back(cb.min[a]);
      edge_hi[static_cast<std::size_t>(a)].push_back(cb.max[a]);
    }
  std::uint64_t shell_cells = 0;  // cells met but not held whole, summed over the boxes
  for (const world::Box& o : map.obstacles()) {
    grown.push_back(o.inflated(radius));
    const world::Box& g = grown.back();
    BoxCells r;
    for (int a = 0; a < 3; ++a) {
      r.lo[a] = std::max(0, static_cast<int>(std::ceil((g.min[a] - b.min[a]) / c[a] - 1.0)));
      r.hi[a] = std::min(dims[a] - 1, static_cast<int>(std::floor((g.max[a] - b.min[a]) / c[a])));
      const auto& lo_edges = edge_lo[static_cast<std::size_t>(a)];
      const auto& hi_edges = edge_hi[static_cast<std::size_t>(a)];
      // Both edges grow with i: the first cell starting at or above g.min, the last ending at or
      // below g.max.
      r.inner_lo[a] = static_cast<int>(std::lower_bound(lo_edges.begin(), lo_edges.end(), g.min[a]) - lo_edges.begin());
      r.inner_hi[a] = static_cast<int>(std::upper_bound(hi_edges.begin(), hi_edges.end(), g.max[a]) - hi_edges.begin()) - 1;
      r.inner_lo[a] = std::max(r.inner_lo[a], r.lo[a]);
      r.inner_hi[a] = std::min(r.inner_hi[a], r.hi[a]);
    }
    if ((r.lo.array() <= r.hi.array()).all()) {
      const std::uint64_t met = static_cast<std::uint64_t>(r.hi.x() - r.lo.x() + 1) *
                                static_cast<std::uint64_t>(r.hi.y() - r.lo.y() + 1) *
                                static_cast<std::uint64_t>(r.hi.z() - r.lo.z() + 1);
      shell_cells += met - (r.has_inner() ? static_cast<std::uint64_t>(r.inner_hi.x() - r.inner_lo.x() + 1) *
                                                static_cast<std::uint64_t>(r.inner_hi.y() - r.inner_lo.y() + 1) *
                                                static_cast<std::uint64_t>(r.inner_hi.z() - r.inner_lo.z() + 1)
                                          : 0);
    }
    range.push_back(r);
  }
  // Work is bounded by the cells the boxes meet without holding them (issue 20: 20 000 boxes
  // each spanning the map cost 29 s and 80 000 ran out of time): refused past the bound.
  if (shell_cells > kMaxEncodeShellCells)
    throw Error("map: its " + std::to_string(grown.size()) + " obstacles, grown by the robot radius, meet " +
                std::to_string(shell_cells) + " cells of the " + std::to_string(dims.x()) + " x " +
                std::to_string(dims.y()) + " x " + std::to_string(dims.z()) +
                " heuristic grid without covering them, more than the bound " + std::to_string(kMaxEncodeShellCells) +
                " (merge overlapping boxes, or give the map as voxels)");

  // Cells inside a grown box are solid: a 3-D difference array over the inner ranges, summed
  // (O(boxes + cells), never per box per cell).
  const std::size_t px = static_cast<std::size_t>(dims.x()) + 1, py = static_cast<std::size_t>(dims.y()) + 1;
  std::vector<std::int32_t>& cover = scratch.cover;
  cover.assign(px * py * (static_cast<std::size_t>(dims.z()) + 1), 0);
  const auto at = [&](int i, int j, int k) -> std::int32_t& {
    return cover[(static_cast<std::size_t>(k) * py + static_cast<std::size_t>(j)) * px + static_cast<std::size_t>(i)];
  };
  for (const BoxCells& r : range) {
    if (!r.has_inner()) continue;
    const int x[2] = {r.inner_lo.x(), r.inner_hi.x() + 1}, y[2] = {r.inner_lo.y(), r.inner_hi.y() + 1},
              z[2] = {r.inner_lo.z(), r.inner_hi.z() + 1};
    for (int q = 0; q < 8; ++q) at(x[q & 1], y[(q >> 1) & 1], z[q >> 2]) += (__builtin_popcount(q) & 1) ? -1 : 1;
  }
  // Prefix sums along x (each row), then y (row += the row before), then z (plane += the plane
  // before): contiguous loops.
  const std::size_t pz = static_cast<std::size_t>(dims.z()) + 1, plane = px * py;
  std::int32_t* d = cover.data();
  for (std::size_t row = 0; row < py * pz; ++row)
    for (std::size_t i = 1; i < px; ++i) d[row * px + i] += d[row * px + i - 1];
  for (std::size_t k = 0; k < pz; ++k)
    for (std::size_t q = k * plane + px; q < (k + 1) * plane; ++q) d[q] += d[q - px];
  for (std::size_t q = plane; q < plane * pz; ++q) d[q] += d[q - plane];
  for (int k = 0; k < dims.z(); ++k)
    for (int j = 0; j < dims.y(); ++j)
      for (int i = 0; i < dims.x(); ++i)
        if (at(i, j, k) > 0) e[cell_index(dims, i, j, k)] = kSolid;

  // Obstacles meeting each other cell (met, not held whole, and not solid already), as one flat
  // list (offsets per cell): count, then fill. Only each box's shell is walked.
  std::vector<std::uint32_t>& offset = scratch.offset;
  offset.assign(cells + 1, 0);
  const auto for_each_cell = [&](std::size_t o, auto&& f) {
    const BoxCells& r = range[o];
    const bool has_inner = r.has_inner();
    for (int k = r.lo.z(); k <= r.hi.z(); ++k)
      for (int j = r.lo.y(); j <= r.hi.y(); ++j) {
        const bool inner_row =
            has_inner && k >= r.inner_lo.z() && k <= r.inner_hi.z() && j >= r.inner_lo.y() && j <= r.inner_hi.y();
        const auto visit = [&](int i0, int i1) {
          for (int i = i0; i <= i1; ++i) {
            const std::size_t idx = cell_index(dims, i, j, k);
            if (e[idx] != kSolid) f(idx);
          }
        };
        if (inner_row) {
          visit(r.lo.x(), r.inner_lo.x() - 1);
          visit(r.inner_hi.x() + 1, r.hi.x());
        } else {
          visit(r.lo.x(), r.hi.x());
        }
      }
  };
  for (std::size_t o = 0; o < grown.size(); ++o) for_each_cell(o, [&](std::size_t idx) { ++offset[idx + 1]; });
  for (std::size_t idx = 0; idx < cells; ++idx) offset[idx + 1] += offset[idx];
  std::vector<std::uint32_t>& touching = scratch.touching;
  touching.resize(offset[cells]);
  // Filled with offset[idx] as the cursor (from idx's start to its end, which is where idx + 1
  // starts), then shifted back one cell: no second array of cells + 1 entries (issue 16: the
  // query's large temporaries were mapped afresh, and page-faulted, on every call).
  for (std::size_t o = 0; o < grown.size(); ++o)
    for_each_cell(o, [&](std::size_t idx) { touching[offset[idx]++] = static_cast<std::uint32_t>(o); });
  for (std::size_t idx = cells; idx > 0; --idx) offset[idx] = offset[idx - 1];
  offset[0] = 0;

  // Blocked sub-cells of the partial cells the boxes meet, for P (only when asked for): (cell,
  // mask) in increasing cell order, only for those cells (a mask per cell of the grid was 8
  // bytes x 32^3, mapped and cleared on every query).
  std::vector<std::pair<std::uint32_t, std::uint64_t>>& box_blocked = scratch.box_blocked;
  box_blocked.clear();
  std::vector<world::Box>& local = scratch.local;
  constexpr std::uint64_t kAllCentres = ~std::uint64_t{0};
  std::uint64_t cover_budget = kMaxEncodeCoverTests;  // exact cover tests left for this encoding
  for (std::size_t idx = 0; idx < cells; ++idx) {
    if (offset[idx] == offset[idx + 1]) continue;
    e[idx] = kPartial;  // met by a box that does not hold it, and inside none
    const world::Box cell = cell_box(b, dims, cell_coords(dims, idx));
    local.clear();
    double clipped_volume = 0.0;  // sum over the boxes of |box and cell|: the union is no larger
    const SubcellCentres centres(cell);
    std::uint64_t blocked = 0;  // the sub-cell centres inside some box (for P, and E's pre-filter)
    for (std::uint32_t t = offset[idx]; t < offset[idx + 1]; ++t) {
      const world::Box& g = grown[touching[t]];
      const world::Box clipped{g.min.cwiseMax(cell.min), g.max.cwiseMin(cell.max)};
      // A run of consecutive boxes equal within the cell adds nothing (issue 20: 20 000 copies of a box).
      if (!local.empty() && local.back().min == clipped.min && local.back().max == clipped.max) continue;
      clipped_volume += (clipped.max - clipped.min).cwiseMax(0.0).prod();
      blocked |= centres.inside(g);
      local.push_back(clipped);
    }
    // A single box that does not hold the cell does not cover it. Several boxes need the exact
    // cut (box_covered) only when no sub-cell centre is left out (a centre in no box is a point
    // of the cell outside the union) and their volumes together could fill the cell (the
    // union's volume is at most the sum; issue 16: 226k small boxes spent ~50 ms cutting cells
    // they could never fill). The margin keeps rounding of the sum on the safe side.
    constexpr double kVolumeRounding = 1e-9;
    if (local.size() > 1 && clipped_volume >= cell.extent().prod() * (1.0 - kVolumeRounding) && blocked == kAllCentres &&
        box_covered(cell, local, &cover_budget))
      e[idx] = kSolid;
    if (passability && e[idx] == kPartial) box_blocked.emplace_back(static_cast<std::uint32_t>(idx), blocked);
  }
  if (map.voxels()) encode_voxels(map, dims, radius, e);
  if (passability) {
    passability->assign(cells, 0);
    std::size_t next = 0;  // box_blocked's entry for the next cell it holds
    for (std::size_t idx = 0; idx < cells; ++idx) {
      std::uint64_t blocked = 0;
      // An entry is passed even when the voxels made its cell solid.
      if (next < box_blocked.size() && box_blocked[next].first == idx) blocked = box_blocked[next++].second;
      if (e[idx] == kFree) {
        (*passability)[idx] = kPassAll;
      } else if (e[idx] == kPartial) {
        if (map.voxels())
          blocked |= subcells_in_grown_voxels(*map.voxels(), radius, cell_box(b, dims, cell_coords(dims, idx)));
        (*passability)[idx] = passability_of(~blocked);
      }
    }
  }
  return e;
}

}  // namespace

std::vector<std::uint8_t> encode_environment(const world::Map& map, const Eigen::Vector3i& dims, double radius) {
  return encode(map, dims, radius, nullptr);
}

Encoding encode_environment_passability(const world::Map& map, const Eigen::Vector3i& dims, double radius) {
  Encoding out;
  out.environment = encode(map, dims, radius, &out.passability);
  return out;
}

std::uint8_t passability_of(std::uint64_t free_subcells) {
  static_assert(kPassabilitySubcells == 4, "the masks below are for 4^3 sub-cells in one 64-bit word");
  // Bits of the sub-cells with x = 0, y = 0, z = 0 (bit x + 4 y + 16 z); the high faces are
  // these shifted by 3 steps along their axis.
  constexpr std::uint64_t kX0 = 0x1111111111111111ULL, kY0 = 0x000F000F000F000FULL, kZ0 = 0xFFFFULL;
  constexpr std::uint64_t kLow[3] = {kX0, kY0, kZ0};
  constexpr std::uint64_t kHigh[3] = {kX0 << 3, kY0 << 12, kZ0 << 48};
  std::uint8_t bits = 0;
  for (int a = 0; a < 3; ++a) {
    // Flood from the low face through face-adjacent free sub-cells (a shift by 1, 4 or 16 bits,
    // masked so that a step off one side of a row or plane does not wrap onto the next).
    std::uint64_t reached = free_subcells & kLow[a];
    while (true) {
      const std::uint64_t grown = reached | ((reached << 1) & ~kX0) | ((reached >> 1) & ~(kX0 << 3)) |
                                  ((reached << 4) & ~kY0) | ((reached >> 4) & ~(kY0 << 12)) | (reached << 16) |
                                  (reached >> 16);
      const std::uint64_t next = grown & free_subcells;
      if (next == reached) break;
      reached = next;
    }
    if (reached & kHigh[a]) bits |= static_cast<std::uint8_t>(1u << a);
  }
  return bits;
}

std::vector<std::uint8_t> encode_state(const world::Box& b, const Eigen::Vector3i& dims, const Eigen::Vector3d& start,
                                       const Eigen::Vector3d& goal, int dilation) {
  // Tenth campaign L17: a NaN start and a dilation of -1 encoded silently.
  require_finite(start, "state: start");
  require_finite(goal, "state: goal");
  const std::size_t cells = plan::HeuristicRegion::cell_count(dims);
  if (dilation < 0 || dilation > dims.maxCoeff())
    throw Error("state: dilation must be in [0, " + std::to_string(dims.maxCoeff()) + "] cells, got " + std::to_string(dilation));
  std::vector<std::uint8_t> s(cells, 0);
  for (const Eigen::Vector3d& p : {start, goal}) {
    const Eigen::Vector3i c = cell_of(b, dims, p);
    for (int k = std::max(0, c.z() - dilation); k <= std::min(dims.z() - 1, c.z() + dilation); ++k)
      for (int j = std::max(0, c.y() - dilation); j <= std::min(dims.y() - 1, c.y() + dilation); ++j)
        for (int i = std::max(0, c.x() - dilation); i <= std::min(dims.x() - 1, c.x() + dilation); ++i)
          s[cell_index(dims, i, j, k)] = 1;
  }
  return s;
}

namespace {

/// A mask of dims.prod() cells (tenth campaign L17: a mask of 5 cells for 32^3 was read past).
/// Values per branch-free pass of the level and probability checks (a few pages: the pass
/// stays in L1 when it must be re-read to name the offending cell).
constexpr std::size_t kCheckBlock = 4096;

void require_mask(const std::vector<std::uint8_t>& mask, const Eigen::Vector3i& dims) {
  if ((dims.array() < 1).any() || static_cast<double>(dims.x()) * dims.y() * dims.z() != static_cast<double>(mask.size()))
    throw Error("grid mask: " + std::to_string(mask.size()) + " cells for a grid of " + std::to_string(dims.x()) + " x " +
                std::to_string(dims.y()) + " x " + std::to_string(dims.z()));
}

}  // namespace

void require_cell_in_grid(const Eigen::Vector3i& c, const Eigen::Vector3i& dims, const std::string& what) {
  if ((c.array() < 0).any() || (c.array() >= dims.array()).any())
    throw Error(what + " (" + std::to_string(c.x()) + ", " + std::to_string(c.y()) + ", " + std::to_string(c.z()) +
                ") lies outside the " + std::to_string(dims.x()) + " x " + std::to_string(dims.y()) + " x " +
                std::to_string(dims.z()) + " grid");
}

void require_levels(const std::vector<std::uint8_t>& values, std::uint8_t max, const std::string& what) {
  // A branch-free maximum per block (vectorised), the offending cell sought only in a block that
  // holds one: a query checks its 32^3 channels several times (session 34's checks cost +2-7 %
  // of a query as a branch per cell).
  for (std::size_t begin = 0; begin < values.size(); begin += kCheckBlock) {
    const std::size_t end = std::min(values.size(), begin + kCheckBlock);
    std::uint8_t top = 0;
    for (std::size_t v = begin; v < end; ++v) top = std::max(top, values[v]);
    if (top <= max) continue;
    for (std::size_t v = begin; v < end; ++v)
      if (values[v] > max)
        throw Error(what + " cell " + std::to_string(v) + " holds " + std::to_string(values[v]) +
                    ", outside its levels 0.." + std::to_string(max));
  }
}

std::size_t first_non_probability(const std::vector<float>& p) {
  for (std::size_t begin = 0; begin < p.size(); begin += kCheckBlock) {
    const std::size_t end = std::min(p.size(), begin + kCheckBlock);
    unsigned all_in = 1;  // NaN fails both comparisons
    for (std::size_t i = begin; i < end; ++i)
      all_in &= static_cast<unsigned>(p[i] >= 0.0F) & static_cast<unsigned>(p[i] <= 1.0F);
    if (all_in) continue;
    for (std::size_t i = begin; i < end; ++i)
      if (!(p[i] >= 0.0F && p[i] <= 1.0F)) return i;
  }
  return p.size();
}

std::vector<int> label_components(const std::vector<std::uint8_t>& mask, const Eigen::Vector3i& dims) {
  require_mask(mask, dims);
  std::vector<int> label(mask.size(), 0);
  std::deque<std::size_t> queue;
  int next = 0;
  for (std::size_t seed = 0; seed < mask.size(); ++seed) {
    if (!mask[seed] || label[seed]) continue;
    label[seed] = ++next;
    queue.push_back(seed);
    while (!queue.empty()) {
      const Eigen::Vector3i c = cell_coords(dims, queue.front());
      queue.pop_front();
      for (int dk = -1; dk <= 1; ++dk)
        for (int dj = -1; dj <= 1; ++dj)
          for (int di = -1; di <= 1; ++di) {
            const Eigen::Vector3i n = c + Eigen::Vector3i(di, dj, dk);
            if ((n.array() < 0).any() || (n.array() >= dims.array()).any()) continue;
            const std::size_t ni = cell_index(dims, n.x(), n.y(), n.z());
            if (!mask[ni] || label[ni]) continue;
            label[ni] = next;
            queue.push_back(ni);
          }
    }
  }
  return label;
}

std::vector<std::uint8_t> component_of(const std::vector<std::uint8_t>& mask, const Eigen::Vector3i& dims,
                                       std::size_t cell, std::size_t stop) {
  // Fourteenth campaign L1: a cell past the mask, or a mask shorter than the grid, was read out
  // of bounds (SEGV under ASan).
  require_mask(mask, dims);
  if (cell >= mask.size())
    throw Error("component_of: cell index " + std::to_string(cell) + " lies outside the mask's " +
                std::to_string(mask.size()) + " cells");
  std::vector<std::uint8_t> in(mask.size(), 0);
  if (!mask[cell]) return in;
  const auto nx = static_cast<std::size_t>(dims.x()), nxy = nx * static_cast<std::size_t>(dims.y());
  std::vector<std::size_t> queue{cell};
  in[cell] = 1;
  // Index offsets of the 26 neighbours, for cells off the grid's border (no bounds tests).
  std::array<std::ptrdiff_t, 26> offsets{};
  std::size_t k = 0;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
        if (dx || dy || dz)
          offsets[k++] = (static_cast<std::ptrdiff_t>(dz) * dims.y() + dy) * dims.x() + dx;
  auto visit = [&](std::size_t v) {
    if (!mask[v] || in[v]) return;
    in[v] = 1;
    queue.push_back(v);
  };
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const std::size_t u = queue[head];
    if (u == stop) break;
    const int x = static_cast<int>(u % nx), y = static_cast<int>(u / nx % static_cast<std::size_t>(dims.y())),
              z = static_cast<int>(u / nxy);
    if (x > 0 && y > 0 && z > 0 && x + 1 < dims.x() && y + 1 < dims.y() && z + 1 < dims.z()) {
      for (const std::ptrdiff_t o : offsets) visit(static_cast<std::size_t>(static_cast<std::ptrdiff_t>(u) + o));
      continue;
    }
    for (int dz = z > 0 ? -1 : 0; dz <= (z + 1 < dims.z() ? 1 : 0); ++dz)
      for (int dy = y > 0 ? -1 : 0; dy <= (y + 1 < dims.y() ? 1 : 0); ++dy)
        for (int dx = x > 0 ? -1 : 0; dx <= (x + 1 < dims.x() ? 1 : 0); ++dx)
          if (dx || dy || dz) visit(cell_index(dims, x + dx, y + dy, z + dz));
  }
  return in;
}

bool connects(const std::vector<std::uint8_t>& mask, const Eigen::Vector3i& dims, const Eigen::Vector3i& a,
              const Eigen::Vector3i& b) {
  require_mask(mask, dims);
  require_cell_in_grid(a, dims, "grid cell a");
  require_cell_in_grid(b, dims, "grid cell b");
  const std::size_t ia = cell_index(dims, a.x(), a.y(), a.z());
  const std::size_t ib = cell_index(dims, b.x(), b.y(), b.z());
  if (!mask[ia] || !mask[ib]) return false;
  return component_of(mask, dims, ia, ib)[ib] != 0;
}

std::size_t solid_cells_in(const std::vector<std::uint8_t>& mask, const std::vector<std::uint8_t>& env) {
  if (mask.size() != env.size())
    throw Error("solid_cells_in: the region mask has " + std::to_string(mask.size()) + " cells and the environment " +
                std::to_string(env.size()));
  std::size_t n = 0;
  for (std::size_t i = 0; i < mask.size(); ++i) n += (mask[i] && env[i] == kSolid) ? 1 : 0;
  return n;
}

}  // namespace miner::heuristic
