// libFuzzer target: vehicle documents (REQ-FLIGHT-001, REQ-CORE-003).
#include "fuzz_target.hpp"
#include "miner/core/json_io.hpp"
#include "miner/flight/vehicle.hpp"

namespace {
void parse(const std::string& text) { (void)miner::flight::vehicle_from_json(miner::parse_json(text, "fuzz"), "fuzz"); }
}  // namespace

MINER_FUZZ_TARGET(parse)
