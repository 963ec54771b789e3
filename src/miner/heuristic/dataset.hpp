#pragma once
/// \file
/// The sGAN's training data (paper Sec. V-A.1; REQ-HEUR-001..003): random cluttered maps
/// with a random start and goal, the A* path as ground truth, encoded on a fixed heuristic
/// grid over the map bounds as four channels of bytes:
///   E (environment)  0 free, 1 partially occupied, 2 solid (grid.hpp: the cell against the
///                    obstacles grown by the robot radius);
///   S (state)        1 in the 3x3x3 cubes of cells around the start and the goal cells;
///   T (target)       1 in the cells the A* path passes through, dilated to 3x3x3 cubes
///                    (HeuristicRegion::from_path, the same region `miner region astar`
///                    writes and the MINER planner samples), less its solid cells;
///   P (passability)  bits 1 x, 2 y, 4 z: the cell's free space joins its two faces across
///                    that axis (grid.hpp; a door and a wall, both partial in E, differ here).
/// Grid: 32^3 by default. A 100 m sim map gives 3.1 x 3.1 x 1.25 m cells, about a quarter
/// of the preset's smallest obstacle side (4 m) horizontally, so obstacles survive the
/// encoding while a 3D convolution over 32^3 stays within the 5 ms CPU budget of the
/// issue (~0.45 GFLOP per 16->16 channel layer, ../shared/anchors.md).
///
/// Layout on disk (`miner-dataset-v3`; v2 had no hash of the index files, v1 no P): DIR/dataset.json
/// describes everything, with the SHA-256 of every shard and index file; each split
/// (train, val, test) is a series of shards `<split>-NNNNN.bin`, each the raw bytes of
/// uint8[n][4][nz][ny][nx] (channel order E, S, T, P; x fastest), readable with
/// numpy.fromfile(..., dtype=uint8).reshape(n, 4, nz, ny, nx); DIR/<split>-index.json
/// lists each sample's map seed, map bounds, start, goal and A* cost.
///
/// Seeds: sample k (0 <= k < count + test_count) uses map seed splitmix64(seed ^ k), a
/// bijection of k, so the test samples (k >= count) come from map seeds never used in
/// training or validation. The last round(val_fraction count) of the first `count` are the
/// validation split.

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "miner/core/json_io.hpp"
#include "miner/heuristic/grid.hpp"
#include "miner/plan/heuristic_region.hpp"
#include "miner/world/map.hpp"

namespace miner::heuristic {

inline constexpr const char* kDatasetFormat = "miner-dataset-v3";
inline constexpr std::size_t kDatasetChannels = 4;  ///< E, S, T, P
/// What marks a dataset folder `miner dataset` may replace: dataset.json of this format or an
/// earlier one (v1, v2: read no more, regenerated in place).
FolderMarker dataset_folder_marker();

struct DatasetOptions {
  std::string preset = "sim";
  int count = 1000;         ///< train + validation samples
  int test_count = 100;     ///< samples from unseen map seeds
  double val_fraction = 0.1;
  std::uint64_t seed = 1;
  Eigen::Vector3i dims = plan::HeuristicRegion::default_dims();
  int dilation = 1;         ///< 3x3x3 cubes
  int shard_size = 256;     ///< samples per shard file
  int jobs = 1;             ///< worker threads (the output does not depend on it)
  /// Start and goal at least this fraction of the bounds' diagonal apart, so the path
  /// crosses the clutter (the paper's queries span the map).
  double min_separation = 0.5;
  /// Distributed generation (REQ-REPORT-006): this process writes only the shard files j
  /// (numbered per split) with j % shard_count == shard_index, into a part folder that
  /// merge_dataset_parts() joins with the others.
  int shard_index = 0;
  int shard_count = 1;
};

/// Throws miner::Error naming the option unless the options are usable.
void validate(const DatasetOptions& o);

struct Sample {
  std::uint64_t k = 0;  ///< its number in the dataset (make_sample's k)
  std::uint64_t map_seed = 0;
  Eigen::Vector3d start = Eigen::Vector3d::Zero();
  Eigen::Vector3d goal = Eigen::Vector3d::Zero();
  double astar_cost = 0.0;
  /// The map's bounds: the grid covers them, so a cell is (max - min) / dims (the families
  /// draw their extents per map; the sGAN's scale input, sgan.hpp, is computed from them).
  world::Box bounds{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  std::vector<std::uint8_t> environment, state, target, passability;  ///< each dims.prod(), x fastest
};

/// Sample k of the dataset: the preset's map for seed splitmix64(seed ^ k) with a random
/// start and goal (free for the robot radius, min_separation apart, A*-connected; drawn
/// again from the next RNG stream otherwise).
Sample make_sample(const DatasetOptions& o, std::uint64_t k);

/// Generates the whole dataset into `dir` (written as a whole: REQ-CORE-004). Progress
/// goes to `progress` when it is not null.
Json write_dataset(const DatasetOptions& o, const std::string& dir, std::ostream* progress);

/// Joins the part folders of one dataset (same options, every part 0..N-1 exactly once)
/// into `dir`, byte for byte the folder an unsharded run writes. Throws miner::Error
/// naming the mismatch or the missing part; `dir` is written as a whole.
Json merge_dataset_parts(const std::vector<std::string>& parts, const std::string& dir);

/// Regenerates each of `samples` (read from the dataset folder `dir` by read_split) with
/// make_sample from the folder's own options and the sample's k, and refuses the first that
/// differs, naming the sample, the channel (or field) and the cell: a shard edited within its
/// levels and re-hashed changed published figures silently (issue 20, seventh campaign W2).
void verify_samples(const std::string& dir, const std::vector<Sample>& samples);

/// The samples the folder holds of split `split`, from dataset.json alone (checked as read_split
/// checks it: a part of a sharded dataset is refused, naming `dataset --merge`).
std::size_t split_samples_held(const std::string& dir, const std::string& split);

/// Reads split `split` back: one Sample per record (metadata from the index).
std::vector<Sample> read_split(const std::string& dir, const std::string& split);

}  // namespace miner::heuristic
