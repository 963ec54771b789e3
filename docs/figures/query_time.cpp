// docs/figures/query_time.sh: warm region queries (heuristic::query_region, one core) on maps,
// medians of encode, inference, filter and the whole query; see the script.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "miner/heuristic/region_filter.hpp"
#include "miner/heuristic/sgan.hpp"
#include "miner/world/map.hpp"
using namespace miner;
namespace {
double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}
}  // namespace
// query_time REPEATS MAP...: per map, REPEATS queries (noise seeds 1..REPEATS); prints the medians and a checksum of the regions' cells.
int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: query_time REPEATS MAP...\n");
    return 2;
  }
  const int reps = std::atoi(argv[1]);
  const auto sgan = heuristic::Sgan::builtin();
  for (int m = 2; m < argc; ++m) {
    const auto map = world::Map::load(argv[m]);
    const world::Box& b = map.bounds();
    // The map's own query when it has one, else 5 % to 95 % of the diagonal with a 0.3 m robot.
    Eigen::Vector3d s = b.min + 0.05 * (b.max - b.min), g = b.min + 0.95 * (b.max - b.min);
    double radius = 0.3;
    if (map.query()) {
      s = map.query()->start;
      g = map.query()->goal;
      radius = map.query()->robot_radius;
    }
    std::vector<double> enc, inf, fil, all;
    std::size_t cells = 0;
    for (int i = 0; i < reps; ++i) {
      const auto t0 = std::chrono::steady_clock::now();
      const auto q = heuristic::query_region(sgan, map, s, g, radius, static_cast<std::uint64_t>(1 + i));
      all.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      enc.push_back(q.encode_ms);
      inf.push_back(q.inference_ms);
      fil.push_back(q.filter_ms);
      cells += q.region.cells().size();
    }
    std::printf("%s: encode %.3f  inference %.3f  filter %.3f  query %.3f ms (medians of %d)  cells %zu\n", argv[m],
                median(enc), median(inf), median(fil), median(all), reps, cells);
  }
}
