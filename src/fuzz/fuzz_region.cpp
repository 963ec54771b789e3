// libFuzzer target: heuristic region files (REQ-PLAN-005, REQ-CORE-003). A region that loads
// survives its JSON round trip.
#include <cstdlib>

#include "fuzz_target.hpp"
#include "miner/core/json_io.hpp"
#include "miner/plan/heuristic_region.hpp"

namespace {
void parse(const std::string& text) {
  const auto region = miner::plan::HeuristicRegion::from_json(miner::parse_json(text, "fuzz"), "fuzz");
  const miner::Json doc = region.to_json();
  if (miner::plan::HeuristicRegion::from_json(doc, "fuzz-again").to_json() != doc) std::abort();
}
}  // namespace

MINER_FUZZ_TARGET(parse)
