// `miner bench paper` measures the sGAN on maps no training set holds (REQ-REPORT-005).
#include <catch2/catch.hpp>

#include <cstdint>
#include <unordered_set>

#include "bench/paper_bench.hpp"
#include "miner/core/rng.hpp"

TEST_CASE("bench paper's generated heuristic maps are none of a training set's maps", "[REQ-REPORT-005]") {
  // Training sets: seeds 0..63, samples k < 4096 (the map seed rule of miner dataset).
  std::unordered_set<std::uint64_t> trained;
  for (std::uint64_t seed = 0; seed < 64; ++seed)
    for (std::uint64_t k = 0; k < 4096; ++k) trained.insert(miner::splitmix64(seed ^ k));
  // The bench's test split (--count 1: k >= 1) for the same seeds.
  std::size_t seen = 0;
  for (std::uint64_t seed = 0; seed < 64; ++seed)
    for (std::uint64_t k = 1; k < 4096; ++k) seen += trained.count(miner::splitmix64(miner::bench::unseen_heuristic_seed(seed) ^ k));
  CHECK(seen == 0);
  // Without the salt every one of them would have been a training map.
  std::size_t unsalted = 0;
  for (std::uint64_t k = 1; k < 4096; ++k) unsalted += trained.count(miner::splitmix64(std::uint64_t{1} ^ k));
  CHECK(unsalted == 4095);
}
