// Smoke test of `miner bench backend`: the real code path on a tiny configuration, the
// JSON contract, and the agreement check it carries. No timing is asserted.
#include <catch2/catch.hpp>

#include <sstream>

#include "bench/backend_bench.hpp"
#include "cli/cli.hpp"
#include "miner/core/json_io.hpp"

using Catch::Matchers::Contains;

TEST_CASE("bench backend gives one record per method, order and size with the documented fields", "[REQ-TRAJ-009]") {
  std::ostringstream out, err;
  const int code = miner::cli::run_cli({"bench", "backend", "--segments", "3,12", "--orders", "3,4",
                                        "--max-dense-segments", "5", "--budget", "0.01", "--samples", "3", "--json"},
                                       out, err);
  INFO(err.str());
  REQUIRE(code == 0);
  const auto doc = miner::parse_json(out.str(), "stdout");
  REQUIRE(doc.is_array());
  CHECK(doc.size() == 2 * 2 * 4);
  for (const auto& r : doc) {
    for (const char* key : {"method", "order", "segments", "us_per_solve", "skipped"}) CHECK(r.contains(key));
    const bool dense = r["method"] != "minco";
    if (dense && r["segments"] == 12) {
      CHECK(r["skipped"] == true);
      CHECK(r["us_per_solve"].is_null());
    } else {
      CHECK(r["us_per_solve"].get<double>() > 0.0);
      // Every baseline solves the same problem: its coefficients match MINCO's.
      CHECK(r["max_rel_diff"].get<double>() < 1e-6);
    }
  }
}

TEST_CASE("bench backend prints a Table II style table and refuses bad options", "[REQ-TRAJ-009][REQ-CLI-002]") {
  std::ostringstream out, err;
  REQUIRE(miner::cli::run_cli({"bench", "backend", "--segments", "4", "--orders", "3", "--budget", "0.01"}, out, err) == 0);
  CHECK_THAT(out.str(), Contains("minco"));
  CHECK_THAT(out.str(), Contains("kkt-qp"));
  std::ostringstream out2, err2;
  CHECK(miner::cli::run_cli({"bench", "backend", "--methods", "ooqp"}, out2, err2) == 2);
  CHECK_THAT(err2.str(), Contains("--methods: ooqp not in {minco,dense-lu,closed-form,kkt-qp}"));
  miner::bench::BackendBenchOptions bad;
  bad.orders = {5};
  CHECK_THROWS_WITH(miner::bench::run_backend_bench(bad), Contains("--orders: must be 3 or 4"));
  bad = {};
  bad.segments = {0};
  CHECK_THROWS_WITH(miner::bench::run_backend_bench(bad), Contains("--segments: must be at least 1"));
  bad = {};
  bad.budget_s = 0;
  CHECK_THROWS_WITH(miner::bench::run_backend_bench(bad), Contains("must be positive"));
}

TEST_CASE("The backend table keeps every column apart however wide its values", "[REQ-TRAJ-009]") {
  // Issue 20, sixth campaign U14: M = 1000000 and 209888 us read "1000000209888" at a fixed width.
  miner::bench::BackendRecord big;
  big.method = "minco";
  big.order = 4;
  big.segments = 1000000;
  big.us_per_solve = 209888.0;
  miner::bench::BackendRecord dense = big;
  dense.method = "dense-lu-with-a-long-name";
  dense.us_per_solve = 123456789.0;
  dense.ratio_to_minco = 588.2;
  std::ostringstream out;
  miner::bench::print_table({big, dense}, out);
  INFO(out.str());
  CHECK_THAT(out.str(), Contains("4  1000000  209888  123456789 (588.2x)"));
  CHECK_THAT(out.str(), Contains("s  M        minco   dense-lu-with-a-long-name"));
}
