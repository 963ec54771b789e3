// libFuzzer target: map documents (REQ-WORLD-001/002, REQ-CORE-003). Any bytes either load as
// a map or raise miner::Error naming the fault; a map that loads survives its JSON round trip.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "miner/core/error.hpp"
#include "miner/core/json_io.hpp"
#include "miner/world/map.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const miner::world::Map map = miner::world::Map::from_json(miner::parse_json(text, "fuzz"), "fuzz");
    if (map.voxels()) return 0;  // a voxel file outside the fuzzer's control
    const miner::Json doc = map.to_json();
    if (miner::world::Map::from_json(doc, "fuzz-again").to_json() != doc) std::abort();
  } catch (const miner::Error&) {
  }
  return 0;
}
