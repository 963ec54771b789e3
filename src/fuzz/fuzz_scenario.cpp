// libFuzzer target: scenario documents (REQ-FLIGHT-007, REQ-CORE-003), inline vehicle and map
// included. A file a scenario references does not exist here: that is refused like any fault.
#include "fuzz_target.hpp"
#include "miner/core/json_io.hpp"
#include "miner/pipeline/scenario.hpp"

namespace {
void parse(const std::string& text) {
  (void)miner::pipeline::scenario_from_json(miner::parse_json(text, "fuzz"), "fuzz", "/nonexistent-miner-fuzz");
}
}  // namespace

MINER_FUZZ_TARGET(parse)
