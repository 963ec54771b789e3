// docs/figures/sgan_time.sh: warm Sgan::predict timings (median of N queries) on a map; see the script.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include "miner/heuristic/sgan.hpp"
#include "miner/heuristic/grid.hpp"
#include "miner/heuristic/region_filter.hpp"
#include "miner/world/map.hpp"
#include "miner/core/rng.hpp"
using namespace miner;
int main(int argc, char** argv) {
  auto map = world::Map::load(argv[1]);
  int reps = argc > 2 ? atoi(argv[2]) : 200;
  auto sgan = heuristic::Sgan::load_or_builtin(argc > 3 ? argv[3] : "");
  auto dims = sgan.architecture().dims;
  Eigen::Vector3d s = map.bounds().min + 0.05 * (map.bounds().max - map.bounds().min);
  Eigen::Vector3d g = map.bounds().min + 0.95 * (map.bounds().max - map.bounds().min);
  auto enc = heuristic::encode_environment_passability(map, dims, 0.3);
  auto& env = enc.environment;
  auto st = heuristic::encode_state(map.bounds(), dims, s, g, 1);
  std::vector<double> t;
  double sum = 0;
  for (int i = 0; i < reps; ++i) {
    Rng rng(7 + i, 3);
    auto t0 = std::chrono::steady_clock::now();
    auto p = sgan.predict(env, st, enc.passability, map.bounds(), 0.3, rng);
    t.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    for (float v : p) sum += v;
  }
  std::sort(t.begin(), t.end());
  printf("min %.3f  p25 %.3f  median %.3f  (n %d) checksum %.6f\n", t[0], t[t.size()/4], t[t.size()/2], reps, sum);
}
