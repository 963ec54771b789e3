#pragma once
/// \file
/// `miner bench voxels` (REQ-WORLD-017): what a voxel map costs. Load time (read, parse, fill,
/// distance transform), memory, point / segment / ray queries per second on random queries,
/// the A* grid's build time and the sGAN channel-E encoding time, single-threaded.

#include <cstdint>
#include <ostream>
#include <string>

#include "miner/core/json_io.hpp"

namespace miner::bench {

struct VoxelBenchOptions {
  double robot_radius = 0.2;
  std::size_t queries = 100000;   ///< random queries of each kind
  double segment_length = 1.0;    ///< m
  double ray_range = 8.0;         ///< m
  int repeats = 5;                ///< loads, grid builds and encodings timed (median reported)
  std::uint64_t seed = 1;
};

/// Runs the benchmark on the map file `path` (read under its own unknown policy).
Json run_voxel_bench(const std::string& path, const VoxelBenchOptions& options);
/// The human summary of run_voxel_bench's document.
void print_voxel_bench(const Json& doc, std::ostream& out);

}  // namespace miner::bench
