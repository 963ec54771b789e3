// A whole flight: a scenario file (or the built-in indoor one) is planned, smoothed and flown
// in closed loop by the simulated quadrotor, N3, EKF and SE(3) controller.
//
//   fly_scenario [SCENARIO.json]
#include <cstdio>

#include "miner/core/error.hpp"
#include "miner/flight/closed_loop.hpp"
#include "miner/pipeline/scenario.hpp"

int main(int argc, char** argv) {
  try {
    const miner::pipeline::Scenario scenario =
        argc > 1 ? miner::pipeline::load_scenario(argv[1]) : miner::pipeline::default_scenario();
    const miner::pipeline::ReferencePlan reference = miner::pipeline::build_reference(scenario);
    miner::flight::FlyOptions options;
    options.record_log = false;
    const miner::flight::FlightResult flight = miner::pipeline::fly(scenario, reference, options);
    std::printf("%s: %s reference of %.2f s, flown %.2f s; position RMSE %.4f m, %d collisions, goal %s\n",
                scenario.name.c_str(), reference.source.c_str(), reference.trajectory.total_duration(),
                flight.flight_time, flight.position_rmse, flight.collisions,
                flight.goal_reached ? "reached" : "missed");
    return flight.goal_reached && flight.collisions == 0 ? 0 : 3;
  } catch (const miner::Error& e) {
    std::fprintf(stderr, "fly_scenario: %s\n", e.what());
    return 1;
  }
}
