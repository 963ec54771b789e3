// libFuzzer target: trajectory problem files (REQ-TRAJ-006/007, REQ-CORE-003): the problem and
// its allocation request. Only parsing and validation run (no solve: its cost is the back
// end's, bounded by the problem's checked sizes).
#include "fuzz_target.hpp"
#include "miner/core/json_io.hpp"
#include "miner/traj/problem_io.hpp"

namespace {
void parse(const std::string& text) {
  const miner::Json doc = miner::parse_json(text, "fuzz");
  (void)miner::traj::request_from_json(doc, "fuzz");
}
}  // namespace

MINER_FUZZ_TARGET(parse)
