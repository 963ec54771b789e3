#pragma once
/// \file
/// `miner bench sim` (REQ-FLIGHT-010): how much faster than real time the full loop
/// (CVODE dynamics, N3, IMU and pose sensors, EKF, controller) runs on one core. The
/// reference is built once; after one untimed warm-up flight each run flies it without
/// keeping the log; the figure is simulated time / wall time, median over runs.

#include <iosfwd>

#include "miner/core/json_io.hpp"
#include "miner/pipeline/scenario.hpp"

namespace miner::bench {

struct SimBenchOptions {
  int runs = 5;
  double relative_tolerance = 1e-6;  ///< CVODE's
};

struct SimBenchResult {
  std::string scenario;
  int runs = 0;
  double flight_time_s = 0.0;     ///< simulated per run
  double wall_s_median = 0.0;
  double real_time_factor = 0.0;  ///< median
  double real_time_factor_min = 0.0;
  double rhs_per_tick = 0.0;      ///< CVODE right-hand-side evaluations per N3 tick
  double relative_tolerance = 0.0;
  long ticks = 0;
};

SimBenchResult run_sim_bench(const pipeline::Scenario& scenario, const SimBenchOptions& options);
Json to_json(const SimBenchResult& r);
void print_table(const SimBenchResult& r, std::ostream& out);

}  // namespace miner::bench
