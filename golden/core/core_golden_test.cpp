// Goldens of the core capability: the RNG's streams are frozen, because every seeded
// result of the project (maps, benchmarks, flights) depends on them.
#include <catch2/catch.hpp>

#include <cstdio>

#include "miner/core/rng.hpp"
#include "miner/testing/golden.hpp"

namespace {
nlohmann::json stream_values(std::uint64_t seed, std::uint64_t stream) {
  miner::Rng rng(seed, stream);
  nlohmann::json raw = nlohmann::json::array(), uniform = raw, normal = raw, index = raw;
  for (int i = 0; i < 8; ++i) {
    char hex[19];
    std::snprintf(hex, sizeof hex, "0x%016llx", static_cast<unsigned long long>(rng.next_u64()));
    raw.push_back(hex);  // as text: 64-bit integers do not fit a double exactly
  }
  for (int i = 0; i < 8; ++i) uniform.push_back(rng.uniform01());
  for (int i = 0; i < 8; ++i) normal.push_back(rng.normal());
  for (int i = 0; i < 8; ++i) index.push_back(rng.uniform_index(1000));
  return {{"seed", seed}, {"stream", stream}, {"u64", raw}, {"uniform01", uniform},
          {"normal", normal}, {"uniform_index_1000", index}};
}
}  // namespace

TEST_CASE("The RNG streams are frozen across releases and standard libraries", "[REQ-CORE-001][REQ-HARNESS-002]") {
  const nlohmann::json actual = {stream_values(20261122, 0), stream_values(20261122, 5), stream_values(1, 0)};
  // uniform01 is exact (53-bit integer times 2^-53); normal() uses log and sqrt, whose
  // results may differ in the last ulp between libm versions: rel 1e-14.
  MINER_REQUIRE_GOLDEN("core/rng.json", actual, (miner::testing::Tolerance{0.0, 1e-14}));
}
