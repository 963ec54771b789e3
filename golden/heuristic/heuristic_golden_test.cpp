// Goldens of the heuristic capability: dataset samples of a fixed seed (independent of the
// weights) and the shipped sGAN's region on a fixture map (changes when the weights are
// retrained: UPDATE_GOLDEN=1 ctest -L golden, see docs/harness.md).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdio>
#include <numeric>

#include "miner/heuristic/dataset.hpp"
#include "miner/heuristic/region_filter.hpp"
#include "miner/heuristic/sgan.hpp"
#include "miner/heuristic/tensor_file.hpp"
#include "miner/testing/golden.hpp"
#include "miner/world/map.hpp"

namespace heuristic = miner::heuristic;

namespace {

std::string hash(const std::vector<std::uint8_t>& v) {
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(heuristic::fnv1a64(v.data(), v.size())));
  return hex;
}

long count(const std::vector<std::uint8_t>& v, std::uint8_t x) { return std::count(v.begin(), v.end(), x); }

}  // namespace

TEST_CASE("Golden: the first sim dataset samples of seed 1", "[REQ-HEUR-001][REQ-HEUR-002]") {
  heuristic::DatasetOptions o;
  o.preset = "sim";
  o.seed = 1;
  nlohmann::json samples = nlohmann::json::array();
  for (std::uint64_t k = 0; k < 3; ++k) {
    const heuristic::Sample s = heuristic::make_sample(o, k);
    samples.push_back({{"map_seed", std::to_string(s.map_seed)},
                       {"start", miner::vec3_json(s.start)},
                       {"goal", miner::vec3_json(s.goal)},
                       {"astar_cost", s.astar_cost},
                       {"environment", {count(s.environment, 0), count(s.environment, 1), count(s.environment, 2)}},
                       {"state_cells", count(s.state, 1)},
                       {"target_cells", count(s.target, 1)},
                       {"bytes_fnv1a64", {hash(s.environment), hash(s.state), hash(s.target)}}});
  }
  MINER_REQUIRE_GOLDEN("heuristic/dataset-sim-seed-1.json", samples, (miner::testing::Tolerance{1e-9, 1e-12}));
}

TEST_CASE("Golden: the shipped sGAN's region on fixture map sim-1", "[REQ-HEUR-005][REQ-HEUR-007]") {
  const miner::world::Map map = miner::world::Map::load(std::string(MINER_SOURCE_DIR) + "/fixtures/maps/sim-1.json");
  const auto& q = *map.query();
  const heuristic::HeuristicQuery h =
      heuristic::query_region(heuristic::Sgan::builtin(), map, q.start, q.goal, q.robot_radius, 1);
  const double sum = std::accumulate(h.probabilities.begin(), h.probabilities.end(), 0.0);
  const auto& r = h.report;
  // Probabilities summed (tolerance: oneDNN's kernels differ by ISA in the last bits);
  // cell counts exact on this machine kind.
  const nlohmann::json value = {{"probability_sum", sum},         {"raw_cells", r.raw_cells},
                                {"raw_connected", r.raw_connected}, {"raw_safe", r.raw_safe},
                                {"solid_dropped", r.solid_dropped}, {"island_dropped", r.island_dropped},
                                {"bridge_cells", r.bridge_cells},   {"cells", r.cells},
                                {"connected", r.connected},         {"safe", r.safe}};
  MINER_REQUIRE_GOLDEN("heuristic/sgan-sim-1.json", value, (miner::testing::Tolerance{1e-2, 1e-5}));
}
