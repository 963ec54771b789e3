// libFuzzer target: MINER's PLY and PCD readers (REQ-WORLD-018). The first byte picks the
// format; any bytes either parse (finite points only) or raise miner::Error.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "miner/core/error.hpp"
#include "miner/world/point_cloud.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    const auto cloud = miner::world::parse_point_cloud(bytes, data[0] & 1, "fuzz");
    for (const auto& p : cloud.points)
      if (!p.allFinite()) std::abort();
  } catch (const miner::Error&) {
  }
  return 0;
}
