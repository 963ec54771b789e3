#include "miner/plan/heuristic_region.hpp"

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <sstream>
#include <utility>

#include "miner/core/error.hpp"
#include "miner/core/json_io.hpp"
#include "miner/core/text.hpp"
#include "miner/core/rng.hpp"
#include "miner/world/map.hpp"

namespace miner::plan {

namespace {

/// Provenance shown in reports and run folders: one printable line of at most this many bytes
/// (issue 20, S7).
constexpr std::size_t kMaxSourceBytes = 512;

/// A map fingerprint as a region file records it: 16 lower-case hex digits.
std::string fingerprint_hex(std::uint64_t f) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(f));
  return text;
}

/// Why `source` is not a region's source, or "" when it is one.
std::string source_problem(const std::string& source) {
  if (source.size() > kMaxSourceBytes ||
      std::any_of(source.begin(), source.end(), [](char c) { return static_cast<unsigned char>(c) < 0x20 || c == 0x7f; }))
    return "must be one line of at most " + std::to_string(kMaxSourceBytes) + " bytes without control characters";
  return "";
}

// Bounds are compared relative to the map's extent: files written with 17 significant
// digits round-trip exactly, so anything above this is a different map, not rounding.
constexpr double kBoundsRelativeTolerance = 1e-9;

}  // namespace

std::size_t HeuristicRegion::cell_count(const Eigen::Vector3i& dims) {
  if ((dims.array() < 1).any()) {
    throw Error("region dims: every entry must be >= 1, got [" + std::to_string(dims.x()) + ", " +
                std::to_string(dims.y()) + ", " + std::to_string(dims.z()) + "]");
  }
  // In double: nx ny nz of three ints reaches 2^93 and would wrap any integer type.
  const double n = static_cast<double>(dims.x()) * dims.y() * dims.z();
  if (n > static_cast<double>(kMaxCells)) {
    std::ostringstream os;
    os << "region dims: [" << dims.x() << ", " << dims.y() << ", " << dims.z() << "] is " << n
       << " cells, more than the limit of " << kMaxCells;
    throw Error(os.str());
  }
  return static_cast<std::size_t>(n);
}

HeuristicRegion::HeuristicRegion(world::Box bounds, Eigen::Vector3i dims,
                                 std::vector<double> probabilities, double threshold,
                                 std::string source)
    : bounds_(std::move(bounds)),
      dims_(std::move(dims)),
      probabilities_(std::move(probabilities)),
      threshold_(threshold),
      source_(std::move(source)) {
  // The loader's rule, here, so a region made in code saves into a file that loads (sixteenth
  // campaign F7: a source with a newline saved, then was refused).
  if (const std::string why = source_problem(source_); !why.empty()) throw Error("region source: " + why);
  require_finite(bounds_.min, "region bounds.min");
  require_finite(bounds_.max, "region bounds.max");
  // A map's range (REQ-WORLD-002): a region of +-1e300 m has cells of 1e300 m and a volume of
  // 1e302 m^3 that sampling and Lemma 2's radius cannot use (tenth campaign recheck).
  world::require_within_range(bounds_.min, "region bounds.min", " (a map's range)");
  world::require_within_range(bounds_.max, "region bounds.max", " (a map's range)");
  if (!(bounds_.max.array() > bounds_.min.array()).all()) {
    throw Error("region bounds: max " + format_point(bounds_.max) + " must exceed min " +
                format_point(bounds_.min) + " on every axis");
  }
  const std::size_t n = cell_count(dims_);
  if (probabilities_.size() != n) {
    throw Error("region probabilities: expected nx*ny*nz = " + std::to_string(n) + " values, got " +
                std::to_string(probabilities_.size()));
  }
  if (!(threshold_ > 0.0 && threshold_ <= 1.0)) {
    std::ostringstream s;
    s << "region threshold: must be in (0, 1], got " << exact_number(threshold_);
    throw Error(s.str());
  }
  cell_size_ = (bounds_.max - bounds_.min).cwiseQuotient(dims_.cast<double>());
  for (std::size_t i = 0; i < n; ++i) {
    const double p = probabilities_[i];
    if (!(p >= 0.0 && p <= 1.0)) {
      std::ostringstream s;
      s << "region probabilities[" << i << "]: must be a number in [0, 1], got " << exact_number(p);
      throw Error(s.str());
    }
    if (p >= threshold_) cells_.push_back(i);
  }
}

HeuristicRegion HeuristicRegion::from_json(const Json& doc, const std::string& origin) {
  const JsonField root(doc, "", origin);
  root.require_format(kRegionFormat);
  root.only_keys({"format", "bounds", "dims", "threshold", "source", "map_fingerprint", "probabilities"});  // issue 20: no ignored key
  const JsonField jb = root.at("bounds");
  jb.only_keys({"min", "max"});
  world::Box bounds{jb.at("min").vec3(), jb.at("max").vec3()};
  const JsonField jd = root.at("dims");
  if (jd.array_size() != 3) jd.fail("expected an array of 3 integers");
  const Eigen::Vector3i dims(jd.at(std::size_t{0}).integer(), jd.at(1).integer(), jd.at(2).integer());
  const JsonField jp = root.at("probabilities");
  const std::size_t n = jp.array_size();
  std::vector<double> probabilities(n);
  for (std::size_t i = 0; i < n; ++i) probabilities[i] = jp.at(i).number();
  // Required: H depends on it, and a file without one was read with 0.5 (issue 20, fourth
  // campaign); every region MINER writes records it.
  const double threshold = root.at("threshold").number();
  const std::string source = root.has("source") ? root.at("source").string() : "";
  if (const std::string why = source_problem(source); !why.empty()) root.at("source").fail(why);
  std::uint64_t fingerprint = 0;
  if (root.has("map_fingerprint")) {
    const std::string hex = root.at("map_fingerprint").string();
    if (hex.size() != 16 || hex.find_first_not_of("0123456789abcdef") != std::string::npos || hex == std::string(16, '0'))
      root.at("map_fingerprint").fail("must be 16 lower-case hexadecimal digits, not all 0 (a map's fingerprint), got " +
                                      quoted_excerpt(hex));
    fingerprint = std::stoull(hex, nullptr, 16);
  }
  try {
    HeuristicRegion region(bounds, dims, std::move(probabilities), threshold, source);
    region.set_map_fingerprint(fingerprint);
    return region;
  } catch (const Error& e) {
    throw Error(origin + ": " + e.what());
  }
}

HeuristicRegion HeuristicRegion::load(const std::string& path) {
  return from_json(read_json_file(path), path);
}

Json HeuristicRegion::to_json() const {
  Json p = Json::array();
  for (double v : probabilities_) {
    // Binary regions stay compact ("0"/"1" rather than "0.0"/"1.0").
    if (v == 0.0 || v == 1.0) p.push_back(static_cast<int>(v));
    else p.push_back(v);
  }
  Json doc{{"format", kRegionFormat},
          {"bounds", {{"min", vec3_json(bounds_.min)}, {"max", vec3_json(bounds_.max)}}},
          {"dims", Json::array({dims_.x(), dims_.y(), dims_.z()})},
          {"threshold", threshold_},
          {"source", source_},
          {"probabilities", p}};
  if (map_fingerprint_ != 0) doc["map_fingerprint"] = fingerprint_hex(map_fingerprint_);
  return doc;
}

void HeuristicRegion::save(const std::string& path) const {
  write_file_atomic(path, dump_json(to_json(), path));
}

HeuristicRegion HeuristicRegion::from_path(const world::Box& bounds, const Eigen::Vector3i& dims,
                                           const std::vector<Eigen::Vector3d>& path, int dilation,
                                           std::string source) {
  if (dilation < 0 || dilation > kMaxDilation)
    throw Error("region dilation: must be in [0, " + std::to_string(kMaxDilation) + "], got " + std::to_string(dilation));
  if (path.empty()) throw Error("region from path: the path has no points");
  // Every point before any is used (tenth campaign L5: a NaN second point was cast to a cell
  // while the first was being walked).
  for (std::size_t s = 0; s < path.size(); ++s) require_finite(path[s], "region path point " + std::to_string(s));
  HeuristicRegion region(bounds, dims,
                         std::vector<double>(cell_count(dims), 0.0),
                         1.0, std::move(source));
  // A path lies in the region's bounds (fifteenth campaign F2: points outside were clamped onto
  // border cells the path never touches, and coordinates near 1e17 lost the cells crossed).
  for (std::size_t s = 0; s < path.size(); ++s)
    if (!region.bounds_.contains(path[s]))
      throw Error("region from path: point " + std::to_string(s) + " " + format_point(path[s]) +
                  " lies outside the region's bounds " + format_point(bounds.min) + " - " + format_point(bounds.max));
  const Eigen::Vector3d cell = region.cell_size_;
  auto cell_of = [&](const Eigen::Vector3d& p) {
    Eigen::Vector3i c;
    for (int a = 0; a < 3; ++a) {
      const double f = std::floor((p[a] - bounds.min[a]) / cell[a]);
      c[a] = static_cast<int>(std::clamp(f, 0.0, static_cast<double>(dims[a] - 1)));
    }
    return c;
  };
  std::vector<char> on_path(region.probabilities_.size(), 0);
  // Each segment is traversed exactly: the parameters t in (0, 1) where it crosses a cell face
  // of the grid split it into pieces that each lie in one cell, found by the piece's midpoint;
  // both ends' cells count too (fourteenth campaign C2: walking in quarter-cell steps missed
  // cells a segment crossed by less than a step, 0.2 m through one). Faces outside the grid
  // are skipped: the cells there are clamped onto the border cells anyway.
  std::vector<double> cuts;
  for (std::size_t s = 0; s < path.size(); ++s) {
    const Eigen::Vector3d a = path[s];
    const Eigen::Vector3d b = s + 1 < path.size() ? path[s + 1] : path[s];
    cuts.assign({0.0, 1.0});
    for (int ax = 0; ax < 3; ++ax) {
      const double u0 = (a[ax] - bounds.min[ax]) / cell[ax], u1 = (b[ax] - bounds.min[ax]) / cell[ax];
      if (!(u1 != u0)) continue;
      const double lo = std::max(1.0, std::floor(std::min(u0, u1)) + 1.0);
      const double hi = std::min(static_cast<double>(dims[ax] - 1), std::ceil(std::max(u0, u1)) - 1.0);
      for (double k = lo; k <= hi; k += 1.0) cuts.push_back((k - u0) / (u1 - u0));
    }
    std::sort(cuts.begin(), cuts.end());
    const auto mark = [&](const Eigen::Vector3d& p) {
      const Eigen::Vector3i c = cell_of(p);
      on_path[region.index(c.x(), c.y(), c.z())] = 1;
    };
    mark(a);
    mark(b);
    for (std::size_t k = 1; k < cuts.size(); ++k)
      if (cuts[k] > cuts[k - 1]) mark(a + (b - a) * (0.5 * (cuts[k - 1] + cuts[k])));
  }
  for (std::size_t i = 0; i < on_path.size(); ++i) {
    if (!on_path[i]) continue;
    const Eigen::Vector3i c = region.coords(i);
    const Eigen::Vector3i lo = (c.array() - dilation).max(0);
    const Eigen::Vector3i hi = (c.array() + dilation).min(dims.array() - 1);
    for (int k = lo.z(); k <= hi.z(); ++k)
      for (int j = lo.y(); j <= hi.y(); ++j)
        for (int ii = lo.x(); ii <= hi.x(); ++ii) region.probabilities_[region.index(ii, j, k)] = 1.0;
  }
  region.cells_.clear();
  for (std::size_t i = 0; i < region.probabilities_.size(); ++i) {
    if (region.probabilities_[i] >= region.threshold_) region.cells_.push_back(i);
  }
  return region;
}

std::size_t HeuristicRegion::index(int i, int j, int k) const {
  if (i < 0 || j < 0 || k < 0 || i >= dims_.x() || j >= dims_.y() || k >= dims_.z())
    throw Error("region cell (" + std::to_string(i) + ", " + std::to_string(j) + ", " + std::to_string(k) +
                ") lies outside the region's " + std::to_string(dims_.x()) + " x " + std::to_string(dims_.y()) + " x " +
                std::to_string(dims_.z()) + " grid");
  return (static_cast<std::size_t>(k) * static_cast<std::size_t>(dims_.y()) + static_cast<std::size_t>(j)) *
             static_cast<std::size_t>(dims_.x()) +
         static_cast<std::size_t>(i);
}

Eigen::Vector3i HeuristicRegion::coords(std::size_t index) const {
  // Fourteenth campaign L2: index 100000 of an 8^3 region answered (0, 4, 1562), and cell_box a
  // box 976 m above the bounds.
  if (index >= probabilities_.size())
    throw Error("region cell index " + std::to_string(index) + " lies outside the region's " +
                std::to_string(probabilities_.size()) + " cells");
  const auto nx = static_cast<std::size_t>(dims_.x());
  const auto ny = static_cast<std::size_t>(dims_.y());
  return Eigen::Vector3i(static_cast<int>(index % nx), static_cast<int>((index / nx) % ny),
                         static_cast<int>(index / (nx * ny)));
}

world::Box HeuristicRegion::cell_box(std::size_t index) const {
  const Eigen::Vector3d lo = bounds_.min + coords(index).cast<double>().cwiseProduct(cell_size_);
  return {lo, lo + cell_size_};
}

long HeuristicRegion::cell_at(const Eigen::Vector3d& p) const {
  if (!bounds_.contains(p)) return -1;
  Eigen::Vector3i c;
  for (int a = 0; a < 3; ++a) {
    c[a] = std::min(static_cast<int>(std::floor((p[a] - bounds_.min[a]) / cell_size_[a])), dims_[a] - 1);
  }
  return static_cast<long>(index(c.x(), c.y(), c.z()));
}

bool HeuristicRegion::contains(const Eigen::Vector3d& p) const {
  const long c = cell_at(p);
  return c >= 0 && probabilities_[static_cast<std::size_t>(c)] >= threshold_;
}

std::vector<int> HeuristicRegion::hops_to(const Eigen::Vector3d& p) const {
  std::vector<int> hops(probabilities_.size(), -1);
  const long source = cell_at(p);
  if (source < 0) return hops;
  std::vector<std::size_t> queue{static_cast<std::size_t>(source)};
  hops[queue.front()] = 0;
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const std::size_t u = queue[head];
    const Eigen::Vector3i c = coords(u);
    for (int dk = -1; dk <= 1; ++dk)
      for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di) {
          const Eigen::Vector3i n = c + Eigen::Vector3i(di, dj, dk);
          if ((n.array() < 0).any() || (n.array() >= dims_.array()).any()) continue;
          const std::size_t v = index(n.x(), n.y(), n.z());
          if (hops[v] >= 0 || probabilities_[v] < threshold_) continue;
          hops[v] = hops[u] + 1;
          queue.push_back(v);
        }
  }
  return hops;
}

double HeuristicRegion::length_fraction_inside(const std::vector<Eigen::Vector3d>& path) const {
  // Checked (fifteenth campaign F8: a NaN point gave 0, a segment to x = 1e300 gave NaN and
  // asked for ~1e300 steps): finite points, a finite total length; each segment is walked only
  // over its part inside the bounds (no cell lies outside them), so the steps are bounded by
  // the bounds' diagonal over the step, whatever the segment's length.
  for (std::size_t s = 0; s < path.size(); ++s)
    if (!path[s].allFinite())
      throw Error("heuristic region: length_fraction_inside: path point " + std::to_string(s) + " " +
                  format_point(path[s]) + " is not finite");
  const double step = 0.25 * cell_size_.minCoeff();
  double inside = 0.0, total = 0.0;
  for (std::size_t s = 1; s < path.size(); ++s) {
    const Eigen::Vector3d a = path[s - 1], d = path[s] - path[s - 1];
    // norm() squares the components (1e300 overflows); stableNorm() only where it must, so
    // the usual lengths keep norm()'s rounding.
    double length = d.norm();
    if (!std::isfinite(length)) length = d.stableNorm();
    if (!std::isfinite(length))
      throw Error("heuristic region: length_fraction_inside: segment " + std::to_string(s - 1) + " from " +
                  format_point(a) + " to " + format_point(path[s]) + " has no finite length");
    total += length;
    if (length == 0.0) continue;
    // The segment's parameter interval [lo, hi] inside the closed bounds (slab clipping).
    double lo = 0.0, hi = 1.0;
    for (int ax = 0; ax < 3 && lo <= hi; ++ax) {
      if (d[ax] == 0.0) {
        if (a[ax] < bounds_.min[ax] || a[ax] > bounds_.max[ax]) hi = -1.0;
        continue;
      }
      double t0 = (bounds_.min[ax] - a[ax]) / d[ax], t1 = (bounds_.max[ax] - a[ax]) / d[ax];
      if (t0 > t1) std::swap(t0, t1);
      lo = std::max(lo, t0);
      hi = std::min(hi, t1);
    }
    if (!(hi > lo)) continue;
    const double part = length * (hi - lo);
    const int steps = std::max(1, static_cast<int>(std::ceil(part / step)));
    int in = 0;
    for (int t = 0; t < steps; ++t) in += contains(a + d * (lo + (hi - lo) * (t + 0.5) / steps));
    inside += part * in / steps;
  }
  if (!std::isfinite(total))
    throw Error("heuristic region: length_fraction_inside: the path's length overflows a double");
  return total > 0.0 ? std::min(1.0, inside / total) : 0.0;
}

double HeuristicRegion::volume() const { return static_cast<double>(cells_.size()) * cell_size_.prod(); }

Eigen::Vector3d HeuristicRegion::sample(Rng& rng) const {
  if (cells_.empty()) throw Error("heuristic region: sample() on a region with no cell in H");
  const world::Box box = cell_box(cells_[rng.uniform_index(cells_.size())]);
  Eigen::Vector3d p;
  for (int a = 0; a < 3; ++a) p[a] = rng.uniform(box.min[a], box.max[a]);
  return p;
}

void HeuristicRegion::require_matches(const world::Map& map, const std::string& what) const {
  // A moved-from map (fingerprint 0) is no map at all, not another one (seventeenth campaign
  // F23: "built for another map ... other obstacles").
  if (map.fingerprint() == 0)
    throw Error(what + ": the map was moved from (its obstacles and voxels went with the move): check the region "
                "against the map it was moved into");
  const world::Box& mb = map.bounds();
  const double tol = kBoundsRelativeTolerance * (mb.max - mb.min).maxCoeff();
  if (((bounds_.min - mb.min).cwiseAbs().array() > tol).any() ||
      ((bounds_.max - mb.max).cwiseAbs().array() > tol).any()) {
    throw Error(what + ": region bounds " + format_point(bounds_.min) + " - " + format_point(bounds_.max) +
                " do not match the map's bounds " + format_point(mb.min) + " - " + format_point(mb.max));
  }
  if (map_fingerprint_ != 0 && map_fingerprint_ != map.fingerprint())
    throw Error(what + ": the region was built for another map (fingerprint " + fingerprint_hex(map_fingerprint_) +
                ", this map's " + fingerprint_hex(map.fingerprint()) + ": other obstacles, voxels or unknown-space policy " +
                "within the same bounds)");
  if (cells_.empty()) {
    std::ostringstream s;
    s << what << ": region has no cell with probability >= threshold " << threshold_;
    throw Error(s.str());
  }
}

}  // namespace miner::plan
