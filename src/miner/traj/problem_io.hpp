#pragma once
/// \file
/// The trajectory problem and answer files of `miner traj solve` (../shared/design.md,
/// REQ-TRAJ-006):
///   problem: {"order": 3, "points": [[x,y,z], ...], "durations": [...] (optional),
///             "head": [[p],[v],[a]], "tail": [...], "limits": {"v_max": 2, "a_max": 1}}
///   answer:  {"order", "durations", "cost", "coefficients": M arrays of 2s rows [x,y,z],
///             ascending powers of local time}

#include <string>

#include "miner/core/json_io.hpp"
#include "miner/traj/minco.hpp"
#include "miner/traj/trapezoidal_allocation.hpp"

namespace miner::traj {

/// Parses and validates a problem; without "durations" they come from trapezoidal
/// allocation with "limits" (required then). Errors name the field.
MincoProblem problem_from_json(const Json& doc, const std::string& origin);

Json answer_to_json(const PolynomialTrajectory& trajectory);

/// Reads an answer back (what answer_to_json wrote): order 3 or 4, positive finite
/// durations, M segments of 2s finite rows each. Errors name the field.
PolynomialTrajectory trajectory_from_answer_json(const Json& doc, const std::string& origin);

}  // namespace miner::traj
