#pragma once
/// \file
/// What the generated results pages (`bench paper`, `bench suite`) share: fixed-point
/// numbers with a dash for unknown values, the commit the figures come from, and a planner's
/// summary in a campaign.

#include <string>

#include "bench/frontend_bench.hpp"

namespace miner::bench {

/// `v` with `digits` decimals, or "—" when not finite (an unknown or missed value).
std::string fixed(double v, int digits);

/// `git describe --always --dirty` of the working directory, or "unknown".
std::string git_commit();

/// The summary of `planner` in the campaign, or nullptr when it did not run there.
const PlannerSummary* find_summary(const FrontendBenchResult& result, const std::string& planner);

}  // namespace miner::bench
