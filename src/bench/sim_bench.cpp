#include "bench/sim_bench.hpp"

#include <algorithm>
#include <chrono>
#include <iomanip>
#include <ostream>
#include <vector>

#include "miner/core/error.hpp"
#include "miner/flight/closed_loop.hpp"

namespace miner::bench {

SimBenchResult run_sim_bench(const pipeline::Scenario& scenario, const SimBenchOptions& options) {
  if (options.runs < 1) throw Error("bench sim: --runs must be >= 1");
  const pipeline::ReferencePlan reference = pipeline::build_reference(scenario);
  flight::FlyOptions fly_options;
  fly_options.record_log = false;
  fly_options.integrator.relative_tolerance = options.relative_tolerance;
  SimBenchResult r;
  r.scenario = scenario.name;
  r.runs = options.runs;
  r.relative_tolerance = options.relative_tolerance;
  std::vector<double> walls, factors;
  // One untimed flight first: page faults, allocator growth and cold caches belong to
  // process start-up, not to the loop being measured.
  const flight::FlightResult warm = pipeline::fly(scenario, reference, fly_options);
  // A real-time factor of a flight that fails would time a failure as if it were the loop's
  // work (issue 20, fourth campaign: `fly` exits 3 on the scenario, `bench sim` reported).
  if (!warm.goal_reached)
    throw NoSolution("bench sim: the flight of " + scenario.name + " does not reach the goal (final error " +
                     std::to_string(warm.final_position_error) + " m, collisions " + std::to_string(warm.collisions) +
                     "), as `miner fly` reports: a failed flight is not timed");
  for (int i = 0; i < options.runs; ++i) {
    const auto start = std::chrono::steady_clock::now();
    const flight::FlightResult flight = pipeline::fly(scenario, reference, fly_options);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    walls.push_back(wall);
    factors.push_back(flight.flight_time / wall);
    r.flight_time_s = flight.flight_time;
    r.ticks = flight.ticks;
    r.rhs_per_tick = static_cast<double>(flight.rhs_evaluations) / static_cast<double>(flight.ticks);
  }
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  };
  r.wall_s_median = median(walls);
  r.real_time_factor = median(factors);
  r.real_time_factor_min = *std::min_element(factors.begin(), factors.end());
  return r;
}

Json to_json(const SimBenchResult& r) {
  return Json{{"scenario", r.scenario},
              {"runs", r.runs},
              {"flight_time_s", r.flight_time_s},
              {"ticks", r.ticks},
              {"wall_s_median", r.wall_s_median},
              {"real_time_factor", r.real_time_factor},
              {"real_time_factor_min", r.real_time_factor_min},
              {"rhs_per_tick", r.rhs_per_tick},
              {"relative_tolerance", r.relative_tolerance},
              {"threads", 1}};
}

void print_table(const SimBenchResult& r, std::ostream& out) {
  out << "scenario " << r.scenario << ": " << r.runs << " flights of " << std::fixed << std::setprecision(2)
      << r.flight_time_s << " s simulated (" << r.ticks << " ticks at the N3 rate), one thread\n"
      << "  wall time (median)   " << std::setprecision(4) << r.wall_s_median << " s\n"
      << "  real-time factor     " << std::setprecision(1) << r.real_time_factor << "x median, "
      << r.real_time_factor_min << "x worst\n"
      << "  CVODE RHS per tick   " << std::setprecision(2) << r.rhs_per_tick << " (rtol "
      << std::scientific << std::setprecision(0) << r.relative_tolerance << ")\n";
}

}  // namespace miner::bench
