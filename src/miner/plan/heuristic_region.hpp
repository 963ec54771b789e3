#pragma once
/// \file
/// The heuristic region H of Alg. 1 (paper Sec. IV-A): a grid of probabilities over the
/// map's bounds, thresholded into a set of cells, and the Nonuniform(H) sampler that
/// draws uniformly inside those cells (REQ-PLAN-004, REQ-PLAN-005).
///
/// File format `miner-region-v1` (JSON):
///   {"format": "miner-region-v1",
///    "bounds": {"min": [x,y,z], "max": [x,y,z]},   // must equal the map's bounds
///    "dims": [nx, ny, nz],
///    "threshold": 0.5,                               // cell in H iff probability >= threshold
///    "probabilities": [p_0, ..., p_{nx ny nz - 1}],  // in [0,1], x fastest, then y, then z
///    "source": "astar-dilated",                      // optional, one printable line
///    "map_fingerprint": "0123456789abcdef"}          // optional: world::Map::fingerprint of its map
/// Cell (i, j, k) covers bounds.min + ([i, i+1] x [j, j+1] x [k, k+1]) * cell_size with
/// cell_size = (bounds.max - bounds.min) / dims; its index is (k ny + j) nx + i.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "miner/core/json_io.hpp"
#include "miner/world/box.hpp"

namespace miner {
class Rng;
namespace world {
class Map;
}
}  // namespace miner

namespace miner::plan {

inline constexpr const char* kRegionFormat = "miner-region-v1";

class HeuristicRegion {
 public:
  /// Validates dims (each >= 1, product <= kMaxCells), probabilities (count, finite,
  /// in [0, 1]) and threshold (in (0, 1]); throws miner::Error naming the fault.
  HeuristicRegion(world::Box bounds, Eigen::Vector3i dims, std::vector<double> probabilities,
                  double threshold, std::string source = "");

  static constexpr std::size_t kMaxCells = std::size_t{1} << 24;
  /// The heuristic grid's cells per axis: the paper's 32^3 (Sec. IV-A.2), the sGAN's input
  /// and output and the A*-dilated region's default; one constant for every default.
  static constexpr int kGridSide = 32;
  static Eigen::Vector3i default_dims() { return Eigen::Vector3i::Constant(kGridSide); }
  /// Largest dilation of a path region, in cells (from_path, miner dataset, miner region):
  /// 4 cells on each side already make a 9-cell-wide tube, over a quarter of a 32-cell axis.
  static constexpr int kMaxDilation = 4;
  /// nx ny nz, checked without integer wrap: throws miner::Error naming the dims when an
  /// entry is < 1 or the product exceeds kMaxCells (REQ-PLAN-005).
  static std::size_t cell_count(const Eigen::Vector3i& dims);

  static HeuristicRegion from_json(const Json& doc, const std::string& origin);
  static HeuristicRegion load(const std::string& path);
  Json to_json() const;
  void save(const std::string& path) const;

  /// The "ground truth" region of the paper's dataset (Sec. V-A.1): every cell a path
  /// polyline passes through (an exact traversal: the pieces between its crossings of cell
  /// faces, and its points), dilated by `dilation` cells in each direction
  /// (dilation 1 = the 3x3x3 cube around each path cell). Probabilities are 0 or 1. Throws
  /// miner::Error for a path point that is not finite or lies outside the bounds.
  static HeuristicRegion from_path(const world::Box& bounds, const Eigen::Vector3i& dims,
                                   const std::vector<Eigen::Vector3d>& path, int dilation,
                                   std::string source);

  const world::Box& bounds() const { return bounds_; }
  const Eigen::Vector3i& dims() const { return dims_; }
  const Eigen::Vector3d& cell_size() const { return cell_size_; }
  double threshold() const { return threshold_; }
  const std::string& source() const { return source_; }
  /// The world::Map::fingerprint of the map the region was built for, or 0 when unknown (a
  /// region made from numbers, or a file written before it was recorded). require_matches
  /// refuses another map even with the same bounds (sixteenth campaign F4).
  std::uint64_t map_fingerprint() const { return map_fingerprint_; }
  /// The region built for `map` (its fingerprint recorded), or for no known map with 0.
  void set_map_fingerprint(std::uint64_t fingerprint) { map_fingerprint_ = fingerprint; }
  const std::vector<double>& probabilities() const { return probabilities_; }
  /// Indices of the cells in H (probability >= threshold), ascending.
  const std::vector<std::size_t>& cells() const { return cells_; }
  bool empty() const { return cells_.empty(); }
  /// The index of cell (i, j, k), x fastest; throws miner::Error for a cell outside the grid
  /// (sixteenth campaign F9: (40, 0, 0) of a 32^3 grid answered another row's cell).
  std::size_t index(int i, int j, int k) const;
  Eigen::Vector3i coords(std::size_t index) const;
  world::Box cell_box(std::size_t index) const;
  /// Index of the cell holding p, or -1 for a point outside the bounds (the max faces
  /// belong to the last cells).
  long cell_at(const Eigen::Vector3d& p) const;
  /// Breadth-first hop counts through H's cells (26-connected) from the cell holding p:
  /// entry i is the number of steps from cell i to p's cell moving only through cells
  /// of H (p's own cell counts as in H), -1 where no such chain exists.
  std::vector<int> hops_to(const Eigen::Vector3d& p) const;
  /// Whether p lies in a cell of H (points outside the bounds are not).
  bool contains(const Eigen::Vector3d& p) const;
  /// The share of a polyline's length that lies in H (0 for a path of zero length): each
  /// segment is walked over its part inside the bounds in steps of a quarter of the smallest
  /// cell side, a step counting as inside when its midpoint is (REQ-PLAN-020's path trust);
  /// length outside the bounds counts as outside. Throws miner::Error for a point that is not
  /// finite or a length that overflows.
  double length_fraction_inside(const std::vector<Eigen::Vector3d>& path) const;
  /// Lebesgue measure of H: number of cells times the cell volume.
  double volume() const;

  /// Nonuniform(H): a cell of H uniformly, then a point uniformly inside it, which is
  /// the uniform distribution on H since all cells have the same volume. Requires !empty().
  Eigen::Vector3d sample(Rng& rng) const;

  /// Throws miner::Error unless this region fits `map`: same bounds (to 1e-9 of the
  /// extent), the same map when its fingerprint is recorded, and at least one cell in H.
  void require_matches(const world::Map& map, const std::string& what) const;

 private:
  world::Box bounds_;
  Eigen::Vector3i dims_;
  Eigen::Vector3d cell_size_;
  std::vector<double> probabilities_;
  double threshold_;
  std::string source_;
  std::uint64_t map_fingerprint_ = 0;
  std::vector<std::size_t> cells_;
};

}  // namespace miner::plan
