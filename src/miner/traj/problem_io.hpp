#pragma once
/// \file
/// The trajectory problem and answer files of `miner traj solve` (../shared/design.md,
/// REQ-TRAJ-006):
///   problem: {"order": 3, "points": [[x,y,z], ...], "durations": [...] (optional),
///             "head": [[p],[v],[a]], "tail": [...], "limits": {"v_max": 2, "a_max": 1},
///             "allocation": "trapezoid" | "optimise" (optional), "rho": 1 (optional)}
///   Without "durations" they come from "allocation" (default "trapezoid") with "limits";
///   "optimise" minimises J + rho sum T within the limits (REQ-TRAJ-011). Unknown keys are
///   refused.
///   answer:  {"order", "durations", "cost", "coefficients": M arrays of 2s rows [x,y,z],
///             ascending powers of local time}

#include <string>

#include "miner/core/json_io.hpp"
#include <optional>

#include "miner/traj/minco.hpp"
#include "miner/traj/time_allocation.hpp"
#include "miner/traj/trapezoidal_allocation.hpp"

namespace miner::traj {

/// Parses and validates a problem; without "durations" they come from trapezoidal
/// allocation with "limits" (required then). Errors name the field.
MincoProblem problem_from_json(const Json& doc, const std::string& origin);

/// A problem file with its allocation request: `optimise` is set when the durations are to
/// be optimised (then problem.durations hold the trapezoid, the optimiser's start).
struct TrajectoryRequest {
  MincoProblem problem;
  std::optional<AllocationOptions> optimise;
};
/// problem_from_json plus "allocation" and "rho"; `allocation_override` ("trapezoid" or
/// "optimise", from the command line) replaces the file's. Errors name the field.
TrajectoryRequest request_from_json(const Json& doc, const std::string& origin,
                                    const std::string& allocation_override = "",
                                    std::optional<double> rho_override = std::nullopt);

Json answer_to_json(const PolynomialTrajectory& trajectory);
/// The answer with an "allocation" block: method, rho, objective J + rho sum T, the
/// trapezoid's (made feasible) and the stretch it needed, cost, total time, exact peaks
/// and limits, Ceres iterations and message, solve time.
Json answer_to_json(const AllocationResult& result, const AllocationOptions& options);

/// Reads an answer back (what answer_to_json wrote): order 3 or 4, positive finite
/// durations, M segments of 2s finite rows each. Errors name the field.
PolynomialTrajectory trajectory_from_answer_json(const Json& doc, const std::string& origin);

}  // namespace miner::traj
