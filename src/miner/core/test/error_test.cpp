#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

#include "miner/core/error.hpp"

using Catch::Matchers::Contains;

TEST_CASE("require_finite names the field and the bad value", "[REQ-CORE-002]") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH(miner::require_finite(nan, "speed"), Contains("speed: must be a finite number, got nan"));
  CHECK_THROWS_WITH(miner::require_finite(Eigen::Vector3d(0, INFINITY, 0), "start"),
                    Contains("start[1]: must be a finite number, got inf"));
  CHECK_NOTHROW(miner::require_finite(Eigen::Vector3d(1, 2, 3), "start"));
}

TEST_CASE("Errors carry the exit code of their kind", "[REQ-CORE-002]") {
  CHECK(miner::Error("x").code() == miner::ExitCode::kInvalidInput);
  CHECK(miner::NoSolution("y").code() == miner::ExitCode::kNoSolution);
  CHECK(miner::format_point(Eigen::Vector3d(1, 2.5, -3)) == "(1, 2.5, -3)");
}
