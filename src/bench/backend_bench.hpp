#pragma once
/// \file
/// `miner bench backend` (REQ-TRAJ-009): MINCO and the Table II baselines timed on the
/// same seeded problems in one process. Benchmarks may read the clock; tests never do.

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "miner/traj/trapezoidal_allocation.hpp"

namespace miner::bench {

/// The most a back-end benchmark may spend in all: --budget times the number of (method,
/// order, M) configurations (one hour).
inline constexpr double kMaxBackendTotalSeconds = 3600.0;

struct BackendBenchOptions {
  std::vector<int> segments{5, 15, 50, 200, 1000};
  std::vector<int> orders{3, 4};
  std::vector<std::string> methods{"minco", "dense-lu", "closed-form", "kkt-qp"};
  int max_dense_segments = 200;  ///< the O(M^3) baselines are skipped above this
  double budget_s = 0.3;         ///< time spent per (method, order, segments)
  int samples = 15;              ///< timed batches; the median batch is reported
  std::uint64_t seed = 1;
};

struct BackendRecord {
  std::string method;
  int order = 0;
  int segments = 0;
  bool skipped = false;
  double us_per_solve = 0.0;    ///< median over batches
  double min_us = 0.0;          ///< fastest batch
  int samples = 0;
  long reps_per_sample = 0;
  double ratio_to_minco = 0.0;  ///< us_per_solve / MINCO's; NaN (JSON null) when MINCO was not timed
  double max_rel_diff = 0.0;    ///< ||c - c_minco|| / ||c_minco||
};

std::vector<BackendRecord> run_backend_bench(const BackendBenchOptions& options);
/// The same methods on one path (a front end's waypoints), durations by trapezoidal
/// allocation under `limits`, for each of options.orders (options.segments is unused).
std::vector<BackendRecord> run_backend_on_path(const Eigen::MatrixX3d& points, const traj::Limits& limits,
                                               const BackendBenchOptions& options);
nlohmann::json to_json(const std::vector<BackendRecord>& records);
/// A table like the paper's Table II: one row per (order, segments), one column per method.
void print_table(const std::vector<BackendRecord>& records, std::ostream& out);

}  // namespace miner::bench
