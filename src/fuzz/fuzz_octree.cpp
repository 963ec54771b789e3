// libFuzzer target: MINER's OctoMap reader (REQ-WORLD-014). Any bytes either parse or raise
// miner::Error; what parses writes back as .bt bytes that parse to the same voxels.
//
// The reader runs with a bound of kFuzzCells = 2^18 voxels (a 64^3 map) instead of kMaxGridCells
// (2.7e8): a file of a few bytes may legitimately announce a map that large, which the reader
// fills and the writer walks in linear time (~40 s under ASan at -O1, over the 10 s per-input
// limit). That cost is bounded and expected, not a finding; the bound's check is the same code
// with a smaller constant. At 2^22 a campaign's corpus filled with inputs near the bound and
// slowed from ~2 700 to ~200 executions/s; 2^18 cuts the worst input's work 16-fold while every
// branch of the reader (tree walk, depth, colour and stamp fields, the bound itself) stays
// reachable.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "miner/core/error.hpp"
#include "miner/world/octree_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  try {
    constexpr double kFuzzCells = 1 << 18;
    const auto layer = miner::world::parse_octree(bytes, "fuzz", kFuzzCells);
    if (layer->count(miner::world::VoxelState::kUnknown) == layer->size()) return 0;
    const std::string bt = miner::world::octree_bt_bytes(*layer);
    const auto again = miner::world::parse_octree(bt, "fuzz-again");
    if (again->states() != layer->states() || again->origin_cells() != layer->origin_cells()) std::abort();
  } catch (const miner::Error&) {
  }
  return 0;
}
