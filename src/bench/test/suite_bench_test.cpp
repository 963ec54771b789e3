// `miner bench suite` (REQ-REPORT-008): the suite file is read strictly; every (map, eta)
// campaign runs every planner with the step the suite asks for; the difficulty mark, the
// spread and the misses in the tables and plots come from the runs.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <limits>
#include <regex>

#include <unistd.h>

#include "bench/campaign_stats.hpp"
#include "bench/ompl_planners.hpp"
#include "bench/suite_bench.hpp"
#include "miner/core/error.hpp"
#include "miner/core/json_io.hpp"

using Catch::Matchers::Contains;

namespace {

std::string write_suite(const std::string& name, const std::string& text) {
  const auto d = std::filesystem::temp_directory_path() / ("miner_suite_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(d);
  const auto p = (d / name).string();
  std::ofstream(p) << text;
  return p;
}

const char* kTiny = R"({"format": "miner-bench-suite-v1",
  "steps": [0.1, 0.4],
  "band": [1, 1000000],
  "maps": [{"name": "tiny", "preset": "cluttered", "seed": 3, "size": [12, 12, 6], "obstacles": 12}]})";

miner::bench::SuiteBenchOptions tiny_options(const miner::bench::SuiteDefinition& suite) {
  miner::bench::SuiteBenchOptions o;
  o.suite = suite;
  o.suite_file = "tiny.json";
  o.planners = {"rrtstar", "informed"};
  if (miner::bench::ompl_available()) o.planners.push_back("ompl:RRTstar");
  o.runs = 4;
  o.max_iterations = 1500;
  o.time_limit_s = 0.5;
  return o;
}

/// The run records without their wall-clock fields.
miner::Json untimed(miner::Json j) {
  for (auto& cell : j["cells"]) {
    cell.erase("total_s");
    cell.erase("region");
    cell.erase("planners");  // summaries hold medians of times
    for (auto& run : cell["run_records"]) {
      run.erase("time_ms");
      for (const char* stage : {"first", "target"})
        if (run.contains(stage) && run[stage].is_object()) run[stage].erase("time_ms");
    }
  }
  j.erase("total_s");
  return j;
}

}  // namespace

TEST_CASE("A suite file is read strictly", "[REQ-REPORT-008]") {
  using miner::bench::load_suite;
  const auto s = load_suite(write_suite("ok.json", kTiny));
  REQUIRE(s.maps.size() == 1);
  CHECK(s.maps[0].preset == "cluttered");
  CHECK(s.maps[0].overrides.obstacles == 12);
  CHECK(s.step_fractions == std::vector<double>{0.1, 0.4});
  const auto bad = [](const std::string& name, const std::string& from, const std::string& to) {
    std::string text = kTiny;
    const auto at = text.find(from);
    REQUIRE(at != std::string::npos);
    text.replace(at, from.size(), to);
    return write_suite(name, text);
  };
  CHECK_THROWS_WITH(load_suite(bad("key.json", "\"obstacles\"", "\"obstacle\"")),
                    Contains("maps[0].obstacle: unknown key"));
  CHECK_THROWS_WITH(load_suite(bad("top.json", "\"band\"", "\"bands\"")), Contains("bands: unknown key"));
  CHECK_THROWS_WITH(load_suite(bad("fmt.json", "suite-v1", "suite-v2")), Contains("format: expected"));
  CHECK_THROWS_WITH(load_suite(bad("step.json", "0.4]", "1.5]")), Contains("steps[1]: a steering step is a fraction"));
  CHECK_THROWS_WITH(load_suite(bad("rep.json", "0.4]", "0.1]")), Contains("steps[1]: repeated steering step"));
  // Steps a label cannot tell apart, or too small to be a campaign (seventh campaign W4).
  CHECK_THROWS_WITH(load_suite(bad("near.json", "0.4]", "0.10000001]")), Contains("steps[1]: repeated steering step 0.1"));
  CHECK_THROWS_WITH(load_suite(bad("tiny-step.json", "0.4]", "0.0002]")), Contains("steps[1]: a steering step is a fraction of the map's diagonal in [0.001, 1]"));
  CHECK_THROWS_WITH(load_suite(bad("preset.json", "\"cluttered\"", "\"clutered\"")),
                    Contains("maps[0].preset: unknown preset \"clutered\""));
  CHECK_THROWS_WITH(load_suite(bad("band.json", "[1, 1000000]", "[10, 1]")), Contains("band: hi is below lo"));
  // Eighteenth campaign F27: a fractional band was rounded without a word.
  CHECK_THROWS_WITH(load_suite(bad("band-frac.json", "[1, 1000000]", "[700.7, 2000]")), Contains("band[0]"));
  CHECK_THROWS_WITH(load_suite(bad("band-zero.json", "[1, 1000000]", "[0, 2000]")), Contains("band[0]: iterations are at least 1"));
  CHECK_THROWS_WITH(load_suite(bad("name.json", "\"tiny\"", "\"a/b\"")), Contains("maps[0].name: a name is"));
  CHECK_THROWS_WITH(load_suite("/nonexistent/suite.json"), Contains("/nonexistent/suite.json"));
  // Bounded work: each step is a campaign per map (issue 20: 10^5 steps ran for ever), and a
  // step is printed as the file gives it (1e308 was a 47-digit number).
  std::string many = "[";
  for (int k = 1; k <= 17; ++k) many += (k > 1 ? ", " : "") + std::to_string(k / 20.0);
  CHECK_THROWS_WITH(load_suite(bad("many.json", "[0.1, 0.4]", many + "]")), Contains("steps: at most 16 steering steps, got 17"));
  CHECK_THROWS_WITH(load_suite(bad("huge.json", "0.4]", "1e308]")), Contains("got 1e+308"));
}

TEST_CASE("The suite runs every planner at every step and reports spread, n and misses", "[REQ-REPORT-008]") {
  using namespace miner::bench;
  auto suite = load_suite(write_suite("run.json", kTiny));
  const auto o = tiny_options(suite);
  const auto r = run_suite_bench(o, "test", nullptr);
  REQUIRE(r.cells.size() == 2);
  for (std::size_t k = 0; k < 2; ++k) {
    const auto& c = r.cells[k];
    CHECK(c.step_fraction == suite.step_fractions[k]);
    // eta = fraction x the diagonal of the generated map's bounds.
    CHECK(c.result.steer_step == Approx(suite.step_fractions[k] * c.extent.norm()).epsilon(1e-12));
    REQUIRE(c.result.summaries.size() == o.planners.size());
    for (const auto& s : c.result.summaries) CHECK(s.runs == o.runs);
  }
  // A bigger step makes the first solution come sooner for RRT* (same streams).
  const auto first = [&](std::size_t k) -> double {
    for (const auto& s : r.cells[k].result.summaries)
      if (s.planner == "rrtstar") return s.first_iterations;
    return NAN;
  };
  CHECK(first(1) <= first(0));

  const std::string md = suite_markdown(r, "suite");
  // The band mark follows the measured median: [1, 1e6] holds it...
  CHECK(in_paper_band(r.cells[0], r.options.suite));
  CHECK_THAT(md, Contains("**2 of 2 campaigns are at the paper's difficulty**"));
  // ... and a band just above it does not.
  auto strict = r;
  strict.options.suite.band_lo = first(0) + 1;
  strict.options.suite.band_hi = first(0) + 2;
  CHECK_FALSE(in_paper_band(strict.cells[0], strict.options.suite));
  CHECK_THAT(suite_markdown(strict, "suite"), Contains("**0 of 2 campaigns"));
  // Every planner has a row with n and the reached counts in every campaign table.
  for (const auto& p : o.planners) {
    const std::regex row("\\| `" + std::regex_replace(p, std::regex("[*:]"), "\\$&") + "` \\| 4 \\| [0-4]/4 \\|");
    CHECK(std::distance(std::sregex_iterator(md.begin(), md.end(), row), std::sregex_iterator()) == 2);
  }
  CHECK_THAT(md, Contains("median [IQR]") && Contains("mean ± sd") && Contains("Steering step sweep"));
  // The headline counts come from the campaigns: each campaign has one fastest planner.
  const std::regex fastest("Fastest to the target \\(median time, misses as \\+inf\\):(.*) of 2 campaigns");
  std::smatch m;
  REQUIRE(std::regex_search(md, m, fastest));
  int total = 0;
  const std::string counts = m[1];
  const std::regex in(" in ([0-9]+)");
  for (auto it = std::sregex_iterator(counts.begin(), counts.end(), in); it != std::sregex_iterator(); ++it)
    total += std::stoi((*it)[1]);
  CHECK(total == 2);
  CHECK((md.find("`rrtstar` against `ompl:RRTstar`") != std::string::npos) == miner::bench::ompl_available());

  // A campaign where the target is out of reach: misses are shown, in the tables and plots.
  auto missing = r;
  for (auto& run : missing.cells[0].result.runs) run.result.target.reset();
  const std::string md_miss = suite_markdown(missing, "suite");
  CHECK_THAT(md_miss, Contains("miss [miss, miss]") && Contains("[0/4]"));
  const auto figures = suite_figures(missing);
  REQUIRE(figures.size() == 2);
  const std::string& svg = figures.begin()->first.find("-0.1-") != std::string::npos ? figures.begin()->second
                                                                                      : figures.rbegin()->second;
  CHECK(figures.count("tiny-0.1-target.svg") == 1);  // steps named by 6 significant digits (seventh campaign W4)
  CHECK_THAT(svg, Contains("n=4, 4 missed"));

  // A planner that does not count iterations (OMPL's RRTConnect: kUnknownCount) has them
  // written as not counted, not as 2^64 (docs/suite.md printed "18446744073709551616 ± 0"), and
  // its first solutions still count as reached.
  auto uncounted = r;
  const std::string who = o.planners.front();
  int solved = 0;
  for (auto& run : uncounted.cells[0].result.runs)
    if (run.planner == who && run.result.first) {
      ++solved;
      run.result.first->iteration = kUnknownCount;
      if (run.result.target) run.result.target->iteration = kUnknownCount;
    }
  REQUIRE(solved > 0);
  const std::string md_uncounted = suite_markdown(uncounted, "suite");
  CHECK(md_uncounted.find("18446744073709551616") == std::string::npos);
  CHECK(md_uncounted.find("1.8e+19") == std::string::npos);
  CHECK_THAT(md_uncounted, Contains("| `" + who + "` | 4 | " + std::to_string(solved) +
                                   "/4 | not counted by the planner | not counted by the planner | "));

  // Same seed, same records (time fields aside), OMPL's included.
  const auto again = run_suite_bench(o, "test", nullptr);
  CHECK(untimed(to_json(again)) == untimed(to_json(r)));
}

TEST_CASE("A suite map that cannot be generated is refused before any campaign", "[REQ-REPORT-008]") {
  using namespace miner::bench;
  SuiteDefinition s;
  s.step_fractions = {0.1};
  SuiteMap m;
  m.name = "bad";
  m.preset = "cluttered";
  m.overrides.size = Eigen::Vector3d(0.5, 0.5, 0.5);  // too small to hold a query
  s.maps = {m};
  auto o = tiny_options(s);
  CHECK_THROWS_WITH(run_suite_bench(o, "test", nullptr), Contains("maps[0] (\"bad\"): size:"));
}

TEST_CASE("A suite map of voxels made in memory (the scan preset) is benchmarked like any other", "[REQ-REPORT-008]") {
  // Issue 20, sixth campaign U15: a `scan` entry failed mid-run with "map: its voxels were made
  // in memory and have no file to reference" (telling entries apart wrote the map's JSON).
  using namespace miner::bench;
  auto suite = load_suite(write_suite("scan.json", R"({"format": "miner-bench-suite-v1", "steps": [0.1],
    "band": [1, 1000000], "maps": [{"name": "a", "preset": "scan", "seed": 13, "size": [10, 8, 3], "resolution": 0.25},
                                   {"name": "b", "preset": "scan", "seed": 14, "size": [10, 8, 3], "resolution": 0.25}]})"));
  auto o = tiny_options(suite);
  o.planners = {"rrtstar"};
  o.runs = 1;
  const auto r = run_suite_bench(o, "test", nullptr);
  REQUIRE(r.cells.size() == 2);
  CHECK(r.cells[0].preset == "scan");
  // The same recipe twice is still one map benchmarked twice: refused.
  suite.maps[1] = suite.maps[0];
  suite.maps[1].name = "again";
  o.suite = suite;
  CHECK_THROWS_WITH(run_suite_bench(o, "test", nullptr), Contains("maps[1] (\"again\") generates the same map as"));
}

TEST_CASE("The Mann-Whitney test of the headlines matches the textbook values", "[REQ-REPORT-008]") {
  using miner::bench::mann_whitney_p;
  const double inf = std::numeric_limits<double>::infinity();
  // Fully separated samples of 5 and 5: U = 0, z = (12.5 - 0.5) / sqrt(22.917): p = 0.01219
  // (scipy.stats.mannwhitneyu(..., method="asymptotic") gives 0.012185).
  CHECK(mann_whitney_p({1, 2, 3, 4, 5}, {6, 7, 8, 9, 10}) == Approx(0.012185).epsilon(1e-3));
  CHECK(mann_whitney_p({6, 7, 8, 9, 10}, {1, 2, 3, 4, 5}) == Approx(0.012185).epsilon(1e-3));
  // Interleaved samples: no evidence.
  CHECK(mann_whitney_p({1, 3, 5, 7}, {2, 4, 6, 8}) > 0.5);
  // Misses rank above every time and tie among themselves: {1,2,3,inf,inf} vs {4,5,6,7,8}
  // has ranks 1, 2, 3, 9.5, 9.5: U = 25 - 15 = 10, z = (12.5 - 10 - 0.5) / sqrt(25/12 (11 - 6/90)),
  // p = 0.6753.
  CHECK(mann_whitney_p({1, 2, 3, inf, inf}, {4, 5, 6, 7, 8}) == Approx(0.6753).epsilon(2e-3));
  CHECK(mann_whitney_p({1, 1}, {1, 1}) == 1.0);
  CHECK(std::isnan(mann_whitney_p({}, {1})));
}
