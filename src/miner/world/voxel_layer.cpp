#include "miner/world/voxel_layer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "miner/core/error.hpp"
#include "miner/core/text.hpp"
#include "miner/world/map.hpp"

namespace miner::world {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
/// Half a voxel's diagonal, in voxels: no point of a cube lies farther from its centre.
const double kHalfDiagonal = 0.5 * std::sqrt(3.0);
/// The distance field is stored in float (24-bit mantissa): bound B subtracts this share of
/// the stored distance (plus one voxel's worth of it) so float rounding never makes it
/// overstate the distance.
constexpr double kFieldRounding = 1e-6;

/// Squared distance transform of one line (Felzenszwalb & Huttenlocher 2012, Sec. 2.1):
/// out[q] = min_p (q - p)^2 + f[p], over the p with finite f[p] (all +inf when none).
/// The lower envelope is built over finite samples only, so no inf - inf arises.
void distance_transform_1d(const std::vector<double>& f, std::vector<double>& out, std::vector<int>& v,
                           std::vector<double>& z) {
  const int n = static_cast<int>(f.size());
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (!std::isfinite(f[q])) continue;
    double s = -kInf;
    while (k >= 0) {
      const int p = v[k];
      s = ((f[q] + static_cast<double>(q) * q) - (f[p] + static_cast<double>(p) * p)) / (2.0 * (q - p));
      if (s > z[k]) break;
      --k;
    }
    ++k;
    v[k] = q;
    z[k] = k == 0 ? -kInf : s;
    z[k + 1] = kInf;
  }
  if (k < 0) {
    std::fill(out.begin(), out.end(), kInf);
    return;
  }
  int j = 0;
  for (int q = 0; q < n; ++q) {
    while (z[j + 1] < q) ++j;
    const double dq = q - v[j];
    out[q] = dq * dq + f[v[j]];
  }
}

}  // namespace

std::vector<double> squared_distance_transform(const std::vector<std::uint8_t>& seeds, const Eigen::Vector3i& n,
                                               bool cube_to_cube) {
  // Tenth campaign L17/L18: seeds shorter than the grid were read past their end, negative dims
  // escaped as std::length_error.
  if ((n.array() < 1).any() || static_cast<double>(n.x()) * n.y() * n.z() != static_cast<double>(seeds.size()))
    throw Error("distance transform: " + std::to_string(seeds.size()) + " seeds for a grid of " + std::to_string(n.x()) +
                " x " + std::to_string(n.y()) + " x " + std::to_string(n.z()) + " cells");
  std::vector<double> sq(seeds.size());
  for (std::size_t i = 0; i < seeds.size(); ++i) sq[i] = seeds[i] ? 0.0 : kInf;
  const int longest = n.maxCoeff();
  std::vector<double> f(longest), g(longest), out(longest), z(longest + 1);
  std::vector<int> v(longest);
  const std::size_t stride[3] = {1, static_cast<std::size_t>(n.x()), static_cast<std::size_t>(n.x()) * n.y()};
  for (int axis = 0; axis < 3; ++axis) {
    const int len = n[axis];
    f.resize(len);
    g.resize(len);
    out.resize(len);
    const int u = (axis + 1) % 3, w = (axis + 2) % 3;
    for (int b = 0; b < n[w]; ++b)
      for (int a = 0; a < n[u]; ++a) {
        const std::size_t base = a * stride[u] + b * stride[w];
        for (int q = 0; q < len; ++q) f[q] = sq[base + q * stride[axis]];
        if (cube_to_cube) {
          // min_q max(|p - q| - 1, 0)^2 + f(q) = min_q |p - q|^2 + min_{|s| <= 1} f(q + s).
          for (int q = 0; q < len; ++q)
            g[q] = std::min({f[q], q > 0 ? f[q - 1] : kInf, q + 1 < len ? f[q + 1] : kInf});
          distance_transform_1d(g, out, v, z);
        } else {
          distance_transform_1d(f, out, v, z);
        }
        for (int q = 0; q < len; ++q) sq[base + q * stride[axis]] = out[q];
      }
  }
  return sq;
}

UnknownPolicy parse_unknown_policy(const std::string& text, const std::string& what) {
  if (text == "occupied") return UnknownPolicy::kOccupied;
  if (text == "free") return UnknownPolicy::kFree;
  throw Error((what.empty() ? "" : what + ": ") + "unknown-space policy \"" + text +
              "\" is not one of \"occupied\", \"free\"");
}

const char* to_string(UnknownPolicy policy) { return policy == UnknownPolicy::kOccupied ? "occupied" : "free"; }

VoxelLayer::VoxelLayer(Eigen::Vector3i origin_cells, double resolution, Eigen::Vector3i dims,
                       std::vector<std::uint8_t> states)
    : origin_cells_(origin_cells), resolution_(resolution), dims_(dims), states_(std::move(states)) {
  if (!std::isfinite(resolution_) || !(resolution_ > 0.0)) {
    std::ostringstream os;
    os << "voxel resolution: must be positive and finite, got " << exact_number(resolution_);
    throw Error(os.str());
  }
  check_resolution(resolution_, "voxel resolution");
  if ((dims_.array() < 1).any()) throw Error("voxel layer: every dimension must hold at least one voxel");
  // The layer's cells are ints: origin + dims must not wrap (tenth campaign L22: an origin of
  // INT_MAX cells gave bounds whose max lay below their min).
  for (int k = 0; k < 3; ++k)
    if (static_cast<std::int64_t>(origin_cells_[k]) + dims_[k] > std::numeric_limits<int>::max() ||
        static_cast<std::int64_t>(origin_cells_[k]) < std::numeric_limits<int>::min() / 2)
      throw Error("voxel layer: origin cell " + std::to_string(origin_cells_[k]) + " + " + std::to_string(dims_[k]) +
                  " voxels along axis " + std::to_string(k) + " leaves the range of cell indices");
  const double cells = static_cast<double>(dims_.x()) * dims_.y() * dims_.z();
  if (cells > kMaxGridCells) {
    std::ostringstream os;
    os << "voxel layer: " << dims_.x() << " x " << dims_.y() << " x " << dims_.z() << " voxels, more than the "
       << kMaxGridCells << " a map may have";
    throw Error(os.str());
  }
  if (static_cast<double>(states_.size()) != cells) throw Error("voxel layer: state count does not match its dims");
  for (const std::uint8_t s : states_) {
    if (s > static_cast<std::uint8_t>(VoxelState::kUnknown)) throw Error("voxel layer: a state byte is not free, occupied or unknown");
  }
}

Eigen::Vector3i VoxelLayer::coords(std::size_t idx) const {
  const auto nx = static_cast<std::size_t>(dims_.x());
  const auto ny = static_cast<std::size_t>(dims_.y());
  return {static_cast<int>(idx % nx), static_cast<int>((idx / nx) % ny), static_cast<int>(idx / (nx * ny))};
}

std::size_t VoxelLayer::count(VoxelState s) const {
  return static_cast<std::size_t>(std::count(states_.begin(), states_.end(), static_cast<std::uint8_t>(s)));
}

Box VoxelLayer::bounds() const {
  return {origin_cells_.cast<double>() * resolution_, (origin_cells_ + dims_).cast<double>() * resolution_};
}

Box VoxelLayer::cell_box(const Eigen::Vector3i& c) const {
  const Eigen::Vector3i lo = origin_cells_ + c;
  return {lo.cast<double>() * resolution_, (lo + Eigen::Vector3i::Ones()).cast<double>() * resolution_};
}

Eigen::Vector3d VoxelLayer::cell_center(const Eigen::Vector3i& c) const {
  return ((origin_cells_ + c).cast<double>().array() + 0.5).matrix() * resolution_;
}

Eigen::Vector3i VoxelLayer::clamped_cell(const Eigen::Vector3d& p) const {
  Eigen::Vector3i c;
  for (int a = 0; a < 3; ++a) {
    const double u = std::floor(p[a] / resolution_) - origin_cells_[a];
    // Written so that NaN lands on cell 0 (std::clamp passes NaN through, and NaN cast to int
    // is undefined: tenth campaign L1); Map's queries refuse a non-finite point before this.
    c[a] = u >= dims_[a] - 1 ? dims_[a] - 1 : u > 0.0 ? static_cast<int>(u) : 0;
  }
  return c;
}

std::vector<Box> decimated_occupied_boxes(const VoxelLayer& layer, std::size_t max_boxes, int* block) {
  // No picture fits in 0 boxes: the coarsest blocks came back, more than asked (eleventh campaign L4).
  if (max_boxes < 1) throw Error("decimated_occupied_boxes: max_boxes must be at least 1");
  const Eigen::Vector3i& n = layer.dims();
  for (int f = 1;; f *= 2) {
    const Eigen::Vector3i m = (n.array() + f - 1) / f;
    std::vector<std::uint8_t> any(static_cast<std::size_t>(m.x()) * m.y() * m.z(), 0);
    for (int z = 0; z < n.z(); ++z)
      for (int y = 0; y < n.y(); ++y)
        for (int x = 0; x < n.x(); ++x)
          if (layer.state(layer.index(x, y, z)) == VoxelState::kOccupied)
            any[(static_cast<std::size_t>(z / f) * m.y() + y / f) * m.x() + x / f] = 1;
    std::vector<Box> boxes;
    bool fits = true;
    for (int z = 0; z < m.z() && fits; ++z)
      for (int y = 0; y < m.y() && fits; ++y)
        for (int x = 0; x < m.x(); ++x) {
          if (!any[(static_cast<std::size_t>(z) * m.y() + y) * m.x() + x]) continue;
          int end = x;
          while (end + 1 < m.x() && any[(static_cast<std::size_t>(z) * m.y() + y) * m.x() + end + 1]) ++end;
          const Eigen::Vector3i lo(x * f, y * f, z * f);
          const Eigen::Vector3i hi = Eigen::Vector3i((end + 1) * f, (y + 1) * f, (z + 1) * f).cwiseMin(n);
          boxes.push_back({layer.cell_box(lo).min, layer.cell_box(hi - Eigen::Vector3i::Ones()).max});
          x = end;
          if (boxes.size() > max_boxes) {
            fits = false;
            break;
          }
        }
    if (fits || m.maxCoeff() == 1) {
      if (block) *block = f;
      return boxes;
    }
  }
}

VoxelObstacles::VoxelObstacles(std::shared_ptr<const VoxelLayer> layer, UnknownPolicy policy)
    : layer_(std::move(layer)), policy_(policy) {
  if (!layer_) throw Error("voxels: no layer");
  const VoxelLayer& L = *layer_;
  blocked_.resize(L.size());
  for (std::size_t i = 0; i < L.size(); ++i) {
    const auto s = L.state(i);
    blocked_[i] = s == VoxelState::kOccupied || (s == VoxelState::kUnknown && policy_ == UnknownPolicy::kOccupied);
    blocked_count_ += blocked_[i];
  }
  distance_.assign(L.size(), 0.0f);
  if (blocked_count_ == 0) return;
  const std::vector<double> sq = squared_distance_transform(blocked_, L.dims(), false);
  for (std::size_t i = 0; i < L.size(); ++i) distance_[i] = static_cast<float>(std::sqrt(sq[i]));
}

double VoxelObstacles::distance_lower_bound(const Eigen::Vector3d& p) const {
  check_query_point(p, "distance_lower_bound: p");
  if (blocked_count_ == 0) return kInf;
  const VoxelLayer& L = *layer_;
  const Eigen::Vector3i c = L.clamped_cell(p);
  const double d = distance_[L.index(c.x(), c.y(), c.z())];
  const double res = L.resolution();
  return (d * (1.0 - kFieldRounding) - kFieldRounding - kHalfDiagonal) * res - (p - L.cell_center(c)).norm();
}

std::optional<std::size_t> VoxelObstacles::exact_hit(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                                     double radius) const {
  const VoxelLayer& L = *layer_;
  const Eigen::Vector3d lo = a.cwiseMin(b).array() - radius, hi = a.cwiseMax(b).array() + radius;
  Eigen::Vector3i first, last;
  for (int k = 0; k < 3; ++k) {
    // One voxel of slack each side: the exact distance test below decides.
    const double f = std::floor(lo[k] / L.resolution()) - L.origin_cells()[k] - 1.0;
    const double l = std::floor(hi[k] / L.resolution()) - L.origin_cells()[k] + 1.0;
    first[k] = static_cast<int>(std::clamp(f, 0.0, static_cast<double>(L.dims()[k])));
    last[k] = static_cast<int>(std::clamp(l, -1.0, static_cast<double>(L.dims()[k] - 1)));
    if (last[k] < first[k]) return std::nullopt;
  }
  const double r2 = radius * radius;
  const bool point = a == b;
  for (int z = first.z(); z <= last.z(); ++z)
    for (int y = first.y(); y <= last.y(); ++y)
      for (int x = first.x(); x <= last.x(); ++x) {
        const std::size_t idx = L.index(x, y, z);
        if (!blocked_[idx]) continue;
        const Box cube = L.cell_box({x, y, z});
        if ((point ? squared_distance(a, cube) : squared_distance(a, b, cube)) <= r2) return idx;
      }
  return std::nullopt;
}

std::optional<std::size_t> VoxelObstacles::containing_blocked(const Eigen::Vector3d& p) const {
  const VoxelLayer& L = *layer_;
  if (!L.bounds().contains(p)) return std::nullopt;
  const Eigen::Vector3i c = L.clamped_cell(p);
  const std::size_t idx = L.index(c.x(), c.y(), c.z());
  return blocked_[idx] ? std::optional<std::size_t>(idx) : std::nullopt;
}

std::optional<std::size_t> VoxelObstacles::point_hit(const Eigen::Vector3d& p, double radius) const {
  check_query_point(p, "point_hit: p");
  check_query_radius(radius, "point_hit: radius");
  if (blocked_count_ == 0 || distance_lower_bound(p) > radius) return std::nullopt;
  if (const auto inside = containing_blocked(p)) return inside;
  return exact_hit(p, p, radius);
}

std::optional<std::size_t> VoxelObstacles::segment_hit(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                                       double radius) const {
  check_query_point(a, "segment_hit: a");
  check_query_point(b, "segment_hit: b");
  check_query_radius(radius, "segment_hit: radius");
  if (blocked_count_ == 0) return std::nullopt;
  const Eigen::Vector3d d = b - a;
  const double len = d.norm();
  if (!(len > 0.0)) return point_hit(a, radius);
  if (const auto inside = containing_blocked(a)) return inside;
  if (!Box{a.cwiseMin(b).array() - radius, a.cwiseMax(b).array() + radius}.overlaps(layer_->bounds()))
    return std::nullopt;
  const double res = layer_->resolution();
  // Only the part of the segment within `radius` (and a voxel, for rounding) of the layer's
  // bounds can meet a blocked voxel: the walk is clipped to it (slab test), so a segment
  // reaching far beyond the map costs what its part over the map costs (issue 20: 10 km
  // segments over a 10 m map were walked voxel by voxel, 300 queries/s).
  const Box& lb = layer_->bounds();
  double u0 = 0.0, u1 = 1.0;  // the clipped part is a + u d, u in [u0, u1]
  for (int k = 0; k < 3; ++k) {
    const double lo = lb.min[k] - radius - res, hi = lb.max[k] + radius + res;
    if (d[k] == 0.0) {
      if (a[k] < lo || a[k] > hi) return std::nullopt;
      continue;
    }
    double ua = (lo - a[k]) / d[k], ub = (hi - a[k]) / d[k];
    if (ua > ub) std::swap(ua, ub);
    u0 = std::max(u0, ua);
    u1 = std::min(u1, ub);
  }
  if (u0 > u1) return std::nullopt;
  // Steps shorter than half a voxel hand the next voxel's length to the exact test.
  const double min_step = 0.5 * res;
  const double t_end = u1 * len;
  const auto at = [&](double t) -> Eigen::Vector3d { return t >= len ? b : Eigen::Vector3d(a + (t / len) * d); };
  double t = u0 * len;
  while (true) {
    const double clear = distance_lower_bound(at(t)) - radius;
    if (clear > min_step) {
      // Every point within `clear` of at(t) is farther than `radius` from the obstacles.
      if (t + clear > t_end) return std::nullopt;
      t += clear;
      continue;
    }
    const double t1 = std::min(t_end, t + res);
    if (const auto hit = exact_hit(at(t), at(t1), radius)) return hit;
    if (t1 >= t_end) return std::nullopt;
    t = t1;
  }
}

double VoxelObstacles::clearance(const Eigen::Vector3d& p) const {
  check_query_point(p, "clearance: p");
  require_within_range(p, "clearance: p", " (a map's range): no distance is asked that far");
  if (blocked_count_ == 0) return kInf;
  // The nearest blocked cube lies within upper = d_c + |p - centre_c| + half diagonal of p:
  // test the cubes of that ball's box exactly.
  const VoxelLayer& L = *layer_;
  const Eigen::Vector3i c = L.clamped_cell(p);
  const double upper =
      (distance_[L.index(c.x(), c.y(), c.z())] * (1.0 + kFieldRounding) + kFieldRounding + kHalfDiagonal) *
          L.resolution() +
      (p - L.cell_center(c)).norm();
  const Eigen::Vector3d lo = p.array() - upper, hi = p.array() + upper;
  Eigen::Vector3i first, last;
  for (int k = 0; k < 3; ++k) {
    first[k] = static_cast<int>(std::clamp(std::floor(lo[k] / L.resolution()) - L.origin_cells()[k] - 1.0, 0.0,
                                           static_cast<double>(L.dims()[k] - 1)));
    last[k] = static_cast<int>(std::clamp(std::floor(hi[k] / L.resolution()) - L.origin_cells()[k] + 1.0, 0.0,
                                          static_cast<double>(L.dims()[k] - 1)));
  }
  double best = kInf;
  for (int z = first.z(); z <= last.z(); ++z)
    for (int y = first.y(); y <= last.y(); ++y)
      for (int x = first.x(); x <= last.x(); ++x)
        if (blocked_[L.index(x, y, z)]) best = std::min(best, squared_distance(p, L.cell_box({x, y, z})));
  return std::sqrt(best);
}

std::optional<double> VoxelObstacles::raycast(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                                              double max_range) const {
  check_query_point(origin, "raycast: origin");
  check_query_direction(dir, "raycast: dir");
  check_query_radius(max_range, "raycast: max_range");
  if (blocked_count_ == 0) return std::nullopt;
  const VoxelLayer& L = *layer_;
  const Box box = L.bounds();
  // Clip the ray to the layer.
  const auto clipped = ray_interval(box, origin, dir, max_range);
  if (!clipped) return std::nullopt;
  const auto [t0, t1] = *clipped;
  const double res = L.resolution();
  const Eigen::Vector3d entry = origin + t0 * dir;
  Eigen::Vector3i c = L.clamped_cell(entry);
  Eigen::Vector3i step;
  Eigen::Vector3d next, delta;
  for (int k = 0; k < 3; ++k) {
    step[k] = dir[k] > 0.0 ? 1 : (dir[k] < 0.0 ? -1 : 0);
    const double edge = (L.origin_cells()[k] + c[k] + (step[k] > 0 ? 1 : 0)) * res;
    next[k] = step[k] == 0 ? kInf : (edge - origin[k]) / dir[k];
    delta[k] = step[k] == 0 ? kInf : res / std::abs(dir[k]);
  }
  double t = t0;
  while (t <= t1) {
    if (blocked_[L.index(c.x(), c.y(), c.z())]) return t;
    int k = 0;
    if (next[1] < next[k]) k = 1;
    if (next[2] < next[k]) k = 2;
    t = std::max(t, next[k]);
    next[k] += delta[k];
    c[k] += step[k];
    if (c[k] < 0 || c[k] >= L.dims()[k]) return std::nullopt;
  }
  return std::nullopt;
}

}  // namespace miner::world
